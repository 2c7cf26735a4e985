// The [[device]] the knit-device unit tests run: a KH930 on /dev/ttyKNIT knitting knit and
// lace jobs. Shared so the fixtures agree on one machine.
#pragma once

#include "daemon/config.h"

namespace atelier::test {

inline DeviceConfig knitter_device_config(bool autostart) {
  DeviceConfig d;
  d.name = "knitter";
  d.driver = "ayab";
  d.port = "/dev/ttyKNIT";
  d.machine = "kh930";
  d.kinds = {"knit", "lace"};
  d.autostart = autostart;
  return d;
}

}  // namespace atelier::test

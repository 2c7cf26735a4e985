// The systemd unit's network sandbox as the configuration needs it. The shipped unit allows
// no IP at all (RestrictAddressFamilies=AF_UNIX AF_NETLINK, IPAddressDeny=any); with [web]
// enabled, the generator (systemd/atelierd-generator, which runs `atelierd --sandbox-dropin`
// at boot and at `systemctl daemon-reload`) adds a drop-in that allows the listening
// address's family and, through IPAddressAllow=, only the peers of [web] allow_from.
// Pure; any thread.
#pragma once

#include <string>

#include "daemon/config.h"

namespace atelier::web {

// The drop-in's text ("[Service]" and its lines), or only a comment when [web] is off.
std::string sandbox_dropin(const WebConfig& web, const std::string& config_file);

}  // namespace atelier::web

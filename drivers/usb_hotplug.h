// Watches USB devices come and go, so a device worker can take its machine offline when the
// cable is pulled and back online when it returns.
//
// Two sources, same events:
//  - libusb hotplug (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG), netlink/udev on Linux):
//    events arrive as the kernel announces them.
//  - polling, when hotplug is unavailable or refused (some containers), or forced: the device
//    list is read every `poll_interval` and compared with the previous one.
// At start every device already present is reported as `arrived`, so the caller needs no
// separate initial scan. A device is identified by vendor:product:serial and bus-port path; a
// `left` event carries the serial learned at arrival (sysfs no longer has it by then).
//
// Threading: the callback runs on the monitor's own thread, one event at a time, never
// while a libusb call is in progress; it must not throw, must not call stop() and should
// return quickly (it delays later events). start() and stop() are for one controlling thread.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "drivers/usb_device.h"

namespace atelier {

enum class UsbEvent { arrived, left };

struct UsbMonitorOptions {
  std::chrono::milliseconds poll_interval{1000};  // polling mode only
  bool force_polling = false;                      // skip libusb hotplug even if available
  // Polling source; default: libusb's device list. Tests inject a scripted list here
  // (which implies polling).
  std::function<std::vector<UsbDeviceInfo>()> lister;
  std::filesystem::path sysfs_root = "/sys";  // where serial numbers are read
};

class UsbHotplugMonitor {
 public:
  using Callback = std::function<void(UsbEvent, const UsbDeviceInfo&)>;
  enum class Mode { stopped, hotplug, polling };

  explicit UsbHotplugMonitor(Callback callback, UsbMonitorOptions options = {});
  ~UsbHotplugMonitor();  // stops
  UsbHotplugMonitor(const UsbHotplugMonitor&) = delete;
  UsbHotplugMonitor& operator=(const UsbHotplugMonitor&) = delete;

  // Starts the monitor thread. Throws UsbError when libusb cannot be initialised (no lister
  // injected), std::logic_error when already running.
  void start();
  // Stops and joins the thread; no callback runs after it returns. Idempotent. Throws
  // std::logic_error if called from the callback (it would wait for itself).
  void stop();
  // Which source start() chose; `stopped` before start() and after stop().
  Mode mode() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace atelier

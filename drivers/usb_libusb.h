// Internal to drivers/usb_*: the libusb glue shared by enumeration and the hotplug monitor.
// Kept out of usb_device.h so users of the public API do not include <libusb.h>.
#pragma once

#include <libusb.h>

#include <filesystem>
#include <vector>

#include "drivers/usb_device.h"

namespace atelier::usb_detail {

// Owns one libusb context (libusb_init / libusb_exit). Throws UsbError if init fails.
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  libusb_context* get() const { return ctx_; }

 private:
  libusb_context* ctx_ = nullptr;
};

// Describes `dev` from its cached device descriptor, bus and port numbers (no I/O on the
// device, so it is safe inside a hotplug callback); the serial is read from sysfs_root.
UsbDeviceInfo describe(libusb_device* dev, const std::filesystem::path& sysfs_root);

// list_usb_devices on an existing context.
std::vector<UsbDeviceInfo> list(libusb_context* ctx, const std::filesystem::path& sysfs_root);

}  // namespace atelier::usb_detail

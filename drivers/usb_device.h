// Finding a USB serial machine (Arduino with AYAB, GRBL board) by vendor:product[:serial]
// and mapping it to the tty the kernel created for it.
//
// Two halves, joined by the bus-port path ("1-1.4": bus 1, hub port 1, port 4), which is both
// what libusb reports and the device's directory name under /sys/bus/usb/devices:
//  - libusb enumerates the devices (list_usb_devices) without opening them, so no privileges
//    are needed. The serial number is read from sysfs: reading the string descriptor through
//    libusb would mean opening the device, which needs write access to /dev/bus/usb.
//  - sysfs maps a device to its tty: CDC-ACM boards (Arduino Uno/Mega) show
//    <dev>/<dev>:1.0/tty/ttyACM0, usb-serial adapters (FTDI, CH340, CP210x) show
//    <dev>/<dev>:1.0/ttyUSB0. The first interface (in name order) with a tty wins.
// Every function takes `sysfs_root` so tests can point it at a fake tree.
//
// Threading: all functions are reentrant (each libusb call uses its own context).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"
#include "drivers/usb_id.h"

namespace atelier {

// libusb failures and ambiguous matches. The message names the device or libusb call.
class UsbError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

struct UsbDeviceInfo {
  UsbId id;                    // serial empty when the device has none or sysfs is unreadable
  uint8_t bus = 0;             // USB bus number (1-based)
  std::vector<uint8_t> ports;  // port numbers from the root hub down; empty for a root hub
  std::string sysfs_name;      // "1-1.4", or "usb1" for root hub 1

  bool operator==(const UsbDeviceInfo&) const = default;
};

// The entry name under /sys/bus/usb/devices for a device: "B-P1.P2..." or "usbB".
std::string usb_sysfs_name(uint8_t bus, const std::vector<uint8_t>& ports);

// The tty of one device, by sysfs entry name: "/dev/ttyACM0", or nullopt when the entry is
// missing or no interface has a tty (no driver bound yet, or not a serial device).
// Returned paths are always under /dev, whatever `sysfs_root` is.
std::optional<std::string> tty_for_sysfs_device(const std::string& sysfs_name,
                                                const std::filesystem::path& sysfs_root = "/sys");

// sysfs-only lookup: walks sysfs_root/bus/usb/devices/* for a device matching `id` (see
// usb_id_matches) and returns its tty, or nullopt when none matches or it has no tty.
// Throws UsbError when several devices match (two boards with the same vendor:product and
// no serial given), naming them, since picking one would drive the wrong machine.
std::optional<std::string> tty_for_usb(const UsbId& id,
                                       const std::filesystem::path& sysfs_root = "/sys");

// Every USB device libusb sees (root hubs included), in bus-port order. Serial numbers come
// from sysfs_root. Returns an empty vector on a host with no USB devices. Throws UsbError
// when libusb cannot be initialised or cannot list devices.
std::vector<UsbDeviceInfo> list_usb_devices(const std::filesystem::path& sysfs_root = "/sys");

// Picks the device matching `id` from `devices` (from list_usb_devices) and maps it to its
// tty through sysfs. Same results and ambiguity error as tty_for_usb.
std::optional<std::string> find_usb_tty(const UsbId& id, const std::vector<UsbDeviceInfo>& devices,
                                        const std::filesystem::path& sysfs_root = "/sys");

// What the daemon calls for `usb = "..."`: libusb enumerates, sysfs maps. Throws UsbError.
std::optional<std::string> find_usb_tty(const UsbId& id);

}  // namespace atelier

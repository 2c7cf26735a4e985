#include "drivers/usb_device.h"

#include <algorithm>
#include <fstream>
#include <system_error>
#include <tuple>

#include "drivers/usb_libusb.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

fs::path devices_dir(const fs::path& sysfs_root) { return sysfs_root / "bus" / "usb" / "devices"; }

// One sysfs attribute's first line ("2341\n" -> "2341"); nullopt when unreadable.
std::optional<std::string> read_attr(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r' || line.back() == ' '))
    line.pop_back();
  return line;
}

// Directory entry names of `dir` (following symlinks, as sysfs uses them), sorted; empty when
// `dir` is missing or vanishes mid-walk (a device unplugged while we look).
std::vector<std::string> sorted_dirs(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_directory(type_ec)) names.push_back(it->path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The vendor/product/serial of a sysfs device entry; nullopt for interfaces and entries
// without ids.
std::optional<UsbId> read_sysfs_id(const fs::path& dev_dir) {
  const auto vendor = read_attr(dev_dir / "idVendor");
  const auto product = read_attr(dev_dir / "idProduct");
  if (!vendor || !product) return std::nullopt;
  try {
    UsbId id = parse_usb_id(*vendor + ":" + *product);
    id.serial = read_attr(dev_dir / "serial").value_or("");
    return id;
  } catch (const std::invalid_argument&) {
    return std::nullopt;  // not a USB device directory after all
  }
}

// One match among `names`, or nullopt; UsbError when several match.
std::optional<std::string> single_match(const UsbId& id, const std::vector<std::string>& names,
                                        const fs::path& sysfs_root) {
  if (names.empty()) return std::nullopt;
  if (names.size() > 1) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw UsbError("USB id " + to_string(id) + " matches " + std::to_string(names.size()) +
                   " devices (" + list + "); add the serial number to tell them apart");
  }
  return tty_for_sysfs_device(names.front(), sysfs_root);
}

}  // namespace

std::string usb_sysfs_name(uint8_t bus, const std::vector<uint8_t>& ports) {
  if (ports.empty()) return "usb" + std::to_string(bus);
  std::string name = std::to_string(bus) + "-";
  for (size_t i = 0; i < ports.size(); ++i) {
    if (i) name += '.';
    name += std::to_string(ports[i]);
  }
  return name;
}

std::optional<std::string> tty_for_sysfs_device(const std::string& sysfs_name,
                                                const fs::path& sysfs_root) {
  const fs::path dev_dir = devices_dir(sysfs_root) / sysfs_name;
  const std::string iface_prefix = sysfs_name + ":";
  for (const auto& iface : sorted_dirs(dev_dir)) {
    if (iface.rfind(iface_prefix, 0) != 0) continue;
    // CDC-ACM (cdc_acm driver): <iface>/tty/ttyACMn.
    if (const auto ttys = sorted_dirs(dev_dir / iface / "tty"); !ttys.empty())
      return "/dev/" + ttys.front();
    // usb-serial (ftdi_sio, ch341, cp210x): <iface>/ttyUSBn/.
    for (const auto& entry : sorted_dirs(dev_dir / iface))
      if (entry.rfind("tty", 0) == 0 && entry != "tty") return "/dev/" + entry;
  }
  return std::nullopt;
}

std::optional<std::string> tty_for_usb(const UsbId& id, const fs::path& sysfs_root) {
  std::vector<std::string> matches;
  for (const auto& name : sorted_dirs(devices_dir(sysfs_root))) {
    if (name.find(':') != std::string::npos) continue;  // an interface, not a device
    const auto dev = read_sysfs_id(devices_dir(sysfs_root) / name);
    if (dev && usb_id_matches(id, *dev)) matches.push_back(name);
  }
  return single_match(id, matches, sysfs_root);
}

std::vector<UsbDeviceInfo> list_usb_devices(const fs::path& sysfs_root) {
  usb_detail::Context ctx;
  return usb_detail::list(ctx.get(), sysfs_root);
}

std::optional<std::string> find_usb_tty(const UsbId& id, const std::vector<UsbDeviceInfo>& devices,
                                        const fs::path& sysfs_root) {
  std::vector<std::string> matches;
  for (const auto& dev : devices)
    if (usb_id_matches(id, dev.id)) matches.push_back(dev.sysfs_name);
  return single_match(id, matches, sysfs_root);
}

std::optional<std::string> find_usb_tty(const UsbId& id) {
  return find_usb_tty(id, list_usb_devices("/sys"), "/sys");
}

namespace usb_detail {

Context::Context() {
  const int rc = libusb_init(&ctx_);
  if (rc != 0)
    throw UsbError(std::string("libusb_init failed: ") + libusb_strerror(static_cast<libusb_error>(rc)));
}

Context::~Context() { libusb_exit(ctx_); }

UsbDeviceInfo describe(libusb_device* dev, const fs::path& sysfs_root) {
  UsbDeviceInfo info;
  libusb_device_descriptor desc{};
  // Never fails since libusb 1.0.16: the descriptor is cached at enumeration.
  libusb_get_device_descriptor(dev, &desc);
  info.id.vendor = desc.idVendor;
  info.id.product = desc.idProduct;
  info.bus = libusb_get_bus_number(dev);
  uint8_t ports[8];  // USB 3 allows at most 7 tiers below the root hub
  const int n = libusb_get_port_numbers(dev, ports, sizeof ports);
  if (n > 0) info.ports.assign(ports, ports + n);
  info.sysfs_name = usb_sysfs_name(info.bus, info.ports);
  if (desc.iSerialNumber != 0)
    info.id.serial = read_attr(devices_dir(sysfs_root) / info.sysfs_name / "serial").value_or("");
  return info;
}

std::vector<UsbDeviceInfo> list(libusb_context* ctx, const fs::path& sysfs_root) {
  libusb_device** devs = nullptr;
  const ssize_t count = libusb_get_device_list(ctx, &devs);
  if (count < 0)
    throw UsbError(std::string("libusb_get_device_list failed: ") +
                   libusb_strerror(static_cast<libusb_error>(count)));
  std::vector<UsbDeviceInfo> out;
  out.reserve(static_cast<size_t>(count));
  for (ssize_t i = 0; i < count; ++i) out.push_back(describe(devs[i], sysfs_root));
  libusb_free_device_list(devs, 1);
  std::sort(out.begin(), out.end(), [](const UsbDeviceInfo& a, const UsbDeviceInfo& b) {
    return std::tie(a.bus, a.ports) < std::tie(b.bus, b.ports);
  });
  return out;
}

}  // namespace usb_detail
}  // namespace atelier

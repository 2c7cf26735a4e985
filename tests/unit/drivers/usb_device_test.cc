// USB discovery (drivers/usb_device.h): the sysfs tty mapping on fake trees laid out like the
// kernel's, and libusb enumeration on this host.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "drivers/usb_device.h"
#include "drivers/usb_id.h"

namespace fs = std::filesystem;
using namespace atelier;

namespace {

TEST(UsbSysfsName, BusPortPath) {
  EXPECT_EQ(usb_sysfs_name(1, {1, 4}), "1-1.4");
  EXPECT_EQ(usb_sysfs_name(3, {2}), "3-2");
  EXPECT_EQ(usb_sysfs_name(2, {}), "usb2");
}

// A fake sysfs laid out like the kernel's: real directories under devices/pci.../usbN/,
// symlinked from bus/usb/devices/ (devices and interfaces alike).
class UsbSysfs : public ::testing::Test {
 protected:
  enum class Tty { none, acm, usb_serial };

  void SetUp() override {
    std::random_device rd;
    root_ = fs::temp_directory_path() / ("atelier-usb-sysfs-" + std::to_string(rd()));
    fs::create_directories(root_ / "bus/usb/devices");
  }
  void TearDown() override { fs::remove_all(root_); }

  static void write(const fs::path& file, const std::string& text) {
    std::ofstream(file) << text << "\n";
  }

  // Adds device `name` ("1-1.4") with two interfaces; the tty (if any) on interface 1.0.
  void add_device(const std::string& name, const std::string& vid, const std::string& pid,
                  const std::string& serial, Tty tty, const std::string& tty_name = "") {
    const std::string bus = name.substr(0, name.find('-'));
    const fs::path real = root_ / "devices/pci0000:00/0000:00:14.0" / ("usb" + bus) / name;
    fs::create_directories(real);
    write(real / "idVendor", vid);
    write(real / "idProduct", pid);
    if (!serial.empty()) write(real / "serial", serial);
    fs::create_directory_symlink(real, root_ / "bus/usb/devices" / name);
    for (const std::string& iface : {name + ":1.0", name + ":1.1"}) {
      fs::create_directories(real / iface);
      write(real / iface / "bInterfaceNumber", iface.substr(iface.size() - 1));
      fs::create_directory_symlink(real / iface, root_ / "bus/usb/devices" / iface);
    }
    const fs::path first = real / (name + ":1.0");
    if (tty == Tty::acm) fs::create_directories(first / "tty" / tty_name);
    if (tty == Tty::usb_serial) fs::create_directories(first / tty_name / "tty" / tty_name);
  }

  fs::path root_;
};

TEST_F(UsbSysfs, ArduinoUnoMapsToTtyACM) {
  add_device("1-1", "2341", "0043", "75833353035351D0F1A1", Tty::acm, "ttyACM0");
  EXPECT_EQ(tty_for_usb(parse_usb_id("2341:0043"), root_), "/dev/ttyACM0");
  EXPECT_EQ(tty_for_sysfs_device("1-1", root_), "/dev/ttyACM0");
}

TEST_F(UsbSysfs, UsbSerialAdapterMapsToTtyUSB) {
  add_device("1-1", "2341", "0043", "", Tty::acm, "ttyACM0");
  add_device("3-2.1", "1a86", "7523", "", Tty::usb_serial, "ttyUSB1");
  EXPECT_EQ(tty_for_usb(parse_usb_id("1A86:7523"), root_), "/dev/ttyUSB1");
}

TEST_F(UsbSysfs, SerialPicksOneOfTwoIdenticalBoards) {
  add_device("1-1", "2341", "0042", "AAA111", Tty::acm, "ttyACM0");
  add_device("1-2", "2341", "0042", "BBB222", Tty::acm, "ttyACM1");
  EXPECT_EQ(tty_for_usb(parse_usb_id("2341:0042:BBB222"), root_), "/dev/ttyACM1");
  EXPECT_EQ(tty_for_usb(parse_usb_id("2341:0042:AAA111"), root_), "/dev/ttyACM0");
  EXPECT_EQ(tty_for_usb(parse_usb_id("2341:0042:CCC333"), root_), std::nullopt);
}

TEST_F(UsbSysfs, TwoBoardsWithoutSerialIsAnErrorNamingBoth) {
  add_device("1-1", "2341", "0042", "AAA111", Tty::acm, "ttyACM0");
  add_device("1-2", "2341", "0042", "BBB222", Tty::acm, "ttyACM1");
  try {
    tty_for_usb(parse_usb_id("2341:0042"), root_);
    FAIL() << "ambiguous id accepted";
  } catch (const UsbError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("2341:0042"), std::string::npos) << what;
    EXPECT_NE(what.find("1-1"), std::string::npos) << what;
    EXPECT_NE(what.find("1-2"), std::string::npos) << what;
    EXPECT_NE(what.find("serial"), std::string::npos) << what;
  }
}

TEST_F(UsbSysfs, NoMatchingDeviceOrNoTtyIsNullopt) {
  add_device("1-1", "2341", "0043", "", Tty::acm, "ttyACM0");
  add_device("1-3", "046d", "c52b", "", Tty::none);  // a receiver with no serial interface
  EXPECT_EQ(tty_for_usb(parse_usb_id("0403:6001"), root_), std::nullopt);
  EXPECT_EQ(tty_for_usb(parse_usb_id("046d:c52b"), root_), std::nullopt);
  EXPECT_EQ(tty_for_sysfs_device("9-9", root_), std::nullopt);
}

TEST_F(UsbSysfs, HostWithoutUsbBusIsNullopt) {
  EXPECT_EQ(tty_for_usb(parse_usb_id("2341:0043"), root_ / "nonexistent"), std::nullopt);
}

TEST_F(UsbSysfs, LibusbListIsMappedByBusPortPath) {
  add_device("1-1", "2341", "0043", "", Tty::acm, "ttyACM0");
  add_device("2-1.4", "2341", "0043", "SN2", Tty::acm, "ttyACM3");
  const std::vector<UsbDeviceInfo> devices = {
      {{0x1d6b, 0x0002, ""}, 1, {}, "usb1"},
      {{0x2341, 0x0043, ""}, 1, {1}, "1-1"},
      {{0x2341, 0x0043, "SN2"}, 2, {1, 4}, "2-1.4"},
  };
  EXPECT_EQ(find_usb_tty(parse_usb_id("2341:0043:SN2"), devices, root_), "/dev/ttyACM3");
  EXPECT_EQ(find_usb_tty(parse_usb_id("2341:0043:SN9"), devices, root_), std::nullopt);
  EXPECT_THROW(find_usb_tty(parse_usb_id("2341:0043"), devices, root_), UsbError);
  EXPECT_EQ(find_usb_tty(parse_usb_id("2341:0043"), {devices[1]}, root_), "/dev/ttyACM0");
}

TEST(UsbLibusb, ListsDevicesOnThisHost) {
  std::vector<UsbDeviceInfo> devices;
  ASSERT_NO_THROW(devices = list_usb_devices());
  for (const auto& d : devices) {
    EXPECT_NE(d.id.vendor, 0) << d.sysfs_name;
    EXPECT_EQ(d.sysfs_name, usb_sysfs_name(d.bus, d.ports));
  }
  // Whatever is attached, looking up an id nobody makes is "not found", not an error.
  EXPECT_EQ(find_usb_tty(UsbId{0xfffe, 0xfffe, "no-such-serial"}), std::nullopt);
}

}  // namespace

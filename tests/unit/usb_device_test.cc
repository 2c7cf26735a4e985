// USB discovery: id parsing, the sysfs tty mapping on fake trees laid out like the kernel's,
// libusb enumeration on this host, and the hotplug monitor (real libusb and scripted polling).
#include <gtest/gtest.h>

#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>

#include "drivers/usb_device.h"
#include "drivers/usb_hotplug.h"
#include "drivers/usb_id.h"

namespace fs = std::filesystem;
using namespace atelier;

namespace {

TEST(UsbId, ParsesVendorAndProduct) {
  const UsbId id = parse_usb_id("2341:0043");
  EXPECT_EQ(id.vendor, 0x2341);
  EXPECT_EQ(id.product, 0x0043);
  EXPECT_EQ(id.serial, "");
}

TEST(UsbId, ParsesSerialVerbatim) {
  const UsbId id = parse_usb_id("2341:0043:75833353035351D0F1A1");
  EXPECT_EQ(id.vendor, 0x2341);
  EXPECT_EQ(id.product, 0x0043);
  EXPECT_EQ(id.serial, "75833353035351D0F1A1");
}

TEST(UsbId, HexIsCaseInsensitive) {
  EXPECT_EQ(parse_usb_id("1A86:7523"), parse_usb_id("1a86:7523"));
  EXPECT_EQ(parse_usb_id("0403:6001").product, 0x6001);
  EXPECT_EQ(parse_usb_id("3:fFfF").vendor, 3);
  EXPECT_EQ(parse_usb_id("3:fFfF").product, 0xffff);
}

TEST(UsbId, RejectsMalformedTextNamingIt) {
  for (const std::string bad : {"", "2341", "2341:", ":0043", "23410:0043", "2341:00g3",
                                "2341:0043:", "2341:0043:AB CD", "0x2341:0043", "-341:0043"}) {
    try {
      parse_usb_id(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("\"" + bad + "\""), std::string::npos) << e.what();
    }
  }
}

TEST(UsbId, ToStringRoundTrips) {
  EXPECT_EQ(to_string(parse_usb_id("2341:43")), "2341:0043");
  EXPECT_EQ(to_string(parse_usb_id("1A86:7523:ABC:1")), "1a86:7523:ABC:1");
  EXPECT_EQ(parse_usb_id(to_string(UsbId{0x0403, 0x6001, "A50285BI"})),
            (UsbId{0x0403, 0x6001, "A50285BI"}));
}

TEST(UsbId, SerialMattersOnlyWhenAsked) {
  const UsbId device{0x2341, 0x0043, "SN1"};
  EXPECT_TRUE(usb_id_matches({0x2341, 0x0043, ""}, device));
  EXPECT_TRUE(usb_id_matches({0x2341, 0x0043, "SN1"}, device));
  EXPECT_FALSE(usb_id_matches({0x2341, 0x0043, "SN2"}, device));
  EXPECT_FALSE(usb_id_matches({0x2341, 0x0042, ""}, device));
  EXPECT_FALSE(usb_id_matches({0x2342, 0x0043, ""}, device));
}

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

TEST(UsbHotplug, StartsAndStopsCleanly) {
  UsbHotplugMonitor monitor([](UsbEvent, const UsbDeviceInfo&) {});
  EXPECT_EQ(monitor.mode(), UsbHotplugMonitor::Mode::stopped);
  monitor.start();
  EXPECT_NE(monitor.mode(), UsbHotplugMonitor::Mode::stopped);
  EXPECT_THROW(monitor.start(), std::logic_error);
  monitor.stop();
  EXPECT_EQ(monitor.mode(), UsbHotplugMonitor::Mode::stopped);
  monitor.stop();  // idempotent
  monitor.start();  // restartable
  EXPECT_NE(monitor.mode(), UsbHotplugMonitor::Mode::stopped);
}  // the destructor stops it

TEST(UsbHotplug, ForcedPollingUsesLibusbList) {
  UsbMonitorOptions options;
  options.force_polling = true;
  UsbHotplugMonitor monitor([](UsbEvent, const UsbDeviceInfo&) {}, options);
  monitor.start();
  EXPECT_EQ(monitor.mode(), UsbHotplugMonitor::Mode::polling);
  monitor.stop();
  EXPECT_EQ(monitor.mode(), UsbHotplugMonitor::Mode::stopped);
}

// Polling against a scripted device list: the events a device worker sees on unplug/replug.
class UsbPolling : public ::testing::Test {
 protected:
  struct Seen {
    UsbEvent event;
    UsbDeviceInfo info;
  };

  void SetUp() override {
    UsbMonitorOptions options;
    options.poll_interval = std::chrono::milliseconds(2);
    options.lister = [this] {
      std::lock_guard lock(mu_);
      if (fail_next_) {
        fail_next_ = false;
        throw UsbError("scripted listing failure");
      }
      ++polls_;
      cv_.notify_all();
      return plugged_;
    };
    monitor_ = std::make_unique<UsbHotplugMonitor>(
        [this](UsbEvent e, const UsbDeviceInfo& d) {
          std::lock_guard lock(mu_);
          seen_.push_back({e, d});
          cv_.notify_all();
        },
        options);
  }

  void plug(std::vector<UsbDeviceInfo> devices) {
    std::lock_guard lock(mu_);
    plugged_ = std::move(devices);
  }
  // Waits until `n` events have been seen (generous bound so a hang fails, not blocks).
  std::vector<Seen> wait_events(size_t n) {
    std::unique_lock lock(mu_);
    cv_.wait_for(lock, std::chrono::seconds(20), [&] { return seen_.size() >= n; });
    return seen_;
  }
  // Waits until the monitor has polled `n` more times.
  void wait_polls(int n) {
    std::unique_lock lock(mu_);
    const int target = polls_ + n;
    cv_.wait_for(lock, std::chrono::seconds(20), [&] { return polls_ >= target; });
  }

  const UsbDeviceInfo uno_{{0x2341, 0x0043, "SN1"}, 1, {1}, "1-1"};
  const UsbDeviceInfo ftdi_{{0x0403, 0x6001, "A50285BI"}, 1, {2}, "1-2"};
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<UsbDeviceInfo> plugged_;
  std::vector<Seen> seen_;
  int polls_ = 0;
  bool fail_next_ = false;
  std::unique_ptr<UsbHotplugMonitor> monitor_;
};

TEST_F(UsbPolling, ReportsPresentDevicesThenUnplugAndReplug) {
  plug({uno_, ftdi_});
  monitor_->start();
  EXPECT_EQ(monitor_->mode(), UsbHotplugMonitor::Mode::polling);
  auto seen = wait_events(2);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].event, UsbEvent::arrived);
  EXPECT_EQ(seen[1].event, UsbEvent::arrived);

  plug({ftdi_});  // Uno unplugged
  seen = wait_events(3);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[2].event, UsbEvent::left);
  EXPECT_EQ(seen[2].info, uno_);

  plug({ftdi_, uno_});  // and back
  seen = wait_events(4);
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[3].event, UsbEvent::arrived);
  EXPECT_EQ(seen[3].info, uno_);

  wait_polls(3);  // nothing changed: no more events
  monitor_->stop();
  EXPECT_EQ(seen_.size(), 4u);
}

TEST_F(UsbPolling, AnotherBoardOnTheSamePortIsLeftThenArrived) {
  plug({uno_});
  monitor_->start();
  wait_events(1);
  UsbDeviceInfo other = uno_;
  other.id.serial = "SN2";
  plug({other});
  const auto seen = wait_events(3);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[1].event, UsbEvent::left);
  EXPECT_EQ(seen[1].info.id.serial, "SN1");
  EXPECT_EQ(seen[2].event, UsbEvent::arrived);
  EXPECT_EQ(seen[2].info.id.serial, "SN2");
}

TEST_F(UsbPolling, FailedListingDoesNotReportDevicesGone) {
  plug({uno_});
  monitor_->start();
  wait_events(1);
  {
    std::lock_guard lock(mu_);
    fail_next_ = true;
  }
  wait_polls(3);
  monitor_->stop();
  ASSERT_EQ(seen_.size(), 1u);
  EXPECT_EQ(seen_[0].event, UsbEvent::arrived);
}

TEST_F(UsbPolling, StopFromCallbackIsRefused) {
  bool refused = false;
  UsbMonitorOptions options;
  options.lister = [this] { return std::vector<UsbDeviceInfo>{uno_}; };
  UsbHotplugMonitor* self = nullptr;
  UsbHotplugMonitor monitor(
      [&](UsbEvent, const UsbDeviceInfo&) {
        std::lock_guard lock(mu_);
        try {
          self->stop();
        } catch (const std::logic_error&) {
          refused = true;
        }
        seen_.push_back({UsbEvent::arrived, uno_});
        cv_.notify_all();
      },
      options);
  self = &monitor;
  monitor.start();
  wait_events(1);
  monitor.stop();
  EXPECT_TRUE(refused);
}

}  // namespace

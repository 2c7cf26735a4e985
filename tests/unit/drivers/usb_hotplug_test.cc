// The USB hotplug monitor (drivers/usb_hotplug.h): real libusb, and polling against a scripted
// device list (unplug, replug, failed listings).
#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>

#include "drivers/usb_hotplug.h"

using namespace atelier;

namespace {

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

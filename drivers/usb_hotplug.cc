#include "drivers/usb_hotplug.h"

#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "drivers/usb_libusb.h"

namespace atelier {

struct UsbHotplugMonitor::Impl {
  // The monitor whose thread this is (null elsewhere), so stop() can refuse to join itself
  // without reading `thread`, which start() may still be assigning.
  static thread_local const Impl* running_here;

  Callback callback;
  UsbMonitorOptions options;
  std::atomic<Mode> mode{Mode::stopped};
  std::atomic<bool> stopping{false};
  std::unique_ptr<usb_detail::Context> ctx;
  libusb_hotplug_callback_handle handle = 0;
  std::function<std::vector<UsbDeviceInfo>()> poll_source;  // polling mode
  std::thread thread;

  std::mutex mu;                 // guards everything below
  std::condition_variable wake;  // polling sleep, cut short by stop()
  std::vector<std::pair<UsbEvent, UsbDeviceInfo>> pending;
  std::map<std::string, UsbDeviceInfo> present;  // by sysfs name (hotplug mode)

  // Runs on whichever thread libusb calls it from (the registering thread for the initial
  // enumeration, then the monitor thread); only queues, dispatch() calls the user.
  static int LIBUSB_CALL on_hotplug(libusb_context*, libusb_device* dev,
                                    libusb_hotplug_event event, void* user) {
    auto* self = static_cast<Impl*>(user);
    UsbDeviceInfo info = usb_detail::describe(dev, self->options.sysfs_root);
    std::lock_guard lock(self->mu);
    if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) {
      self->present[info.sysfs_name] = info;
      self->pending.emplace_back(UsbEvent::arrived, std::move(info));
    } else {
      if (auto it = self->present.find(info.sysfs_name); it != self->present.end()) {
        info = it->second;  // keeps the serial read at arrival
        self->present.erase(it);
      }
      self->pending.emplace_back(UsbEvent::left, std::move(info));
    }
    return 0;  // stay registered
  }

  void dispatch() {
    std::vector<std::pair<UsbEvent, UsbDeviceInfo>> events;
    {
      std::lock_guard lock(mu);
      events.swap(pending);
    }
    for (const auto& [event, info] : events) callback(event, info);
  }

  void run_hotplug() {
    running_here = this;
    dispatch();  // the devices enumerated while registering
    while (!stopping) {
      timeval tv{0, 500000};  // a backstop; stop() interrupts the wait at once
      libusb_handle_events_timeout_completed(ctx->get(), &tv, nullptr);
      dispatch();
    }
  }

  static std::string key(const UsbDeviceInfo& d) { return d.sysfs_name + "/" + to_string(d.id); }

  void run_polling() {
    running_here = this;
    std::map<std::string, UsbDeviceInfo> known;
    while (!stopping) {
      bool listed = true;
      std::vector<UsbDeviceInfo> now_list;
      try {
        now_list = poll_source();
      } catch (const std::exception&) {
        listed = false;  // transient (e.g. a device vanished mid-read): keep the last view
      }
      if (listed) {
        std::map<std::string, UsbDeviceInfo> now;
        for (auto& d : now_list) now.emplace(key(d), std::move(d));
        for (const auto& [k, d] : known)
          if (!now.count(k)) callback(UsbEvent::left, d);
        for (const auto& [k, d] : now)
          if (!known.count(k)) callback(UsbEvent::arrived, d);
        known = std::move(now);
      }
      std::unique_lock lock(mu);
      wake.wait_for(lock, options.poll_interval, [this] { return stopping.load(); });
    }
  }
};

thread_local const UsbHotplugMonitor::Impl* UsbHotplugMonitor::Impl::running_here = nullptr;

UsbHotplugMonitor::UsbHotplugMonitor(Callback callback, UsbMonitorOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->callback = std::move(callback);
  impl_->options = std::move(options);
}

UsbHotplugMonitor::~UsbHotplugMonitor() { stop(); }

UsbHotplugMonitor::Mode UsbHotplugMonitor::mode() const { return impl_->mode; }

void UsbHotplugMonitor::start() {
  Impl& m = *impl_;
  if (m.thread.joinable()) throw std::logic_error("UsbHotplugMonitor::start: already running");
  m.stopping = false;
  m.pending.clear();
  m.present.clear();

  m.poll_source = m.options.lister;
  if (!m.poll_source) {
    m.ctx = std::make_unique<usb_detail::Context>();
    if (!m.options.force_polling && libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) {
      const int rc = libusb_hotplug_register_callback(
          m.ctx->get(),
          static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                            LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
          LIBUSB_HOTPLUG_ENUMERATE, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
          LIBUSB_HOTPLUG_MATCH_ANY, &Impl::on_hotplug, &m, &m.handle);
      if (rc == LIBUSB_SUCCESS) {
        m.mode = Mode::hotplug;
        m.thread = std::thread([&m] { m.run_hotplug(); });
        return;
      }
      // Registration refused (no netlink/udev access): poll instead.
    }
    libusb_context* ctx = m.ctx->get();
    const std::filesystem::path root = m.options.sysfs_root;
    m.poll_source = [ctx, root] { return usb_detail::list(ctx, root); };
  }
  m.mode = Mode::polling;
  m.thread = std::thread([&m] { m.run_polling(); });
}

void UsbHotplugMonitor::stop() {
  Impl& m = *impl_;
  if (Impl::running_here == &m)
    throw std::logic_error("UsbHotplugMonitor::stop called from its own callback");
  if (!m.thread.joinable()) return;
  {
    std::lock_guard lock(m.mu);
    m.stopping = true;
  }
  m.wake.notify_all();
  if (m.mode == Mode::hotplug) libusb_interrupt_event_handler(m.ctx->get());
  m.thread.join();
  if (m.mode == Mode::hotplug) libusb_hotplug_deregister_callback(m.ctx->get(), m.handle);
  m.poll_source = nullptr;  // it may point into the context released next
  m.ctx.reset();
  m.mode = Mode::stopped;
}

}  // namespace atelier

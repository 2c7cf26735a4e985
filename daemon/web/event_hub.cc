#include "daemon/web/event_hub.h"

namespace atelier::web {

std::optional<std::string> Subscriber::next(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, timeout, [&] { return ended_ || !queue_.empty(); });
  if (ended_ || queue_.empty()) return std::nullopt;
  std::string message = std::move(queue_.front());
  queue_.pop_front();
  return message;
}

bool Subscriber::ended() {
  std::lock_guard lock(mu_);
  return ended_;
}

EventHub::EventHub(size_t max_streams, size_t max_queued) : max_streams_(max_streams), max_queued_(max_queued) {}

EventHub::~EventHub() { close(); }

std::shared_ptr<Subscriber> EventHub::subscribe() {
  std::lock_guard lock(mu_);
  if (closed_) return nullptr;
  subscribers_.remove_if([](const auto& w) { return w.expired(); });
  if (subscribers_.size() >= max_streams_) return nullptr;
  auto s = std::make_shared<Subscriber>();
  subscribers_.push_back(s);
  return s;
}

void EventHub::publish(const std::string& message) {
  std::lock_guard lock(mu_);
  for (auto it = subscribers_.begin(); it != subscribers_.end();) {
    auto s = it->lock();
    if (!s) {
      it = subscribers_.erase(it);
      continue;
    }
    {
      std::lock_guard slock(s->mu_);
      if (s->queue_.size() >= max_queued_) s->ended_ = true;  // too far behind: it reconnects
      else if (!s->ended_) s->queue_.push_back(message);
    }
    s->cv_.notify_all();
    ++it;
  }
}

void EventHub::close() {
  std::lock_guard lock(mu_);
  closed_ = true;
  for (auto& w : subscribers_) {
    if (auto s = w.lock()) {
      {
        std::lock_guard slock(s->mu_);
        s->ended_ = true;
      }
      s->cv_.notify_all();
    }
  }
  subscribers_.clear();
}

size_t EventHub::streams() {
  std::lock_guard lock(mu_);
  subscribers_.remove_if([](const auto& w) { return w.expired(); });
  return subscribers_.size();
}

std::string sse_message(const std::string& name, const std::string& data) {
  return "event: " + name + "\ndata: " + data + "\n\n";
}

}  // namespace atelier::web

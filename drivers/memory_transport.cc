#include "drivers/memory_transport.h"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>

namespace atelier {

struct MemoryTransport::Shared {
  explicit Shared(Clock& c) : clock(c) {}
  Clock& clock;
  std::mutex mutex;
  std::condition_variable_any changed;
  std::deque<uint8_t> input[2];  // input[i]: bytes waiting to be read by end i
  bool lost = false;
  int dtr_pulses[2] = {0, 0};  // pulse_dtr() calls by each end
};

MemoryTransport::MemoryTransport(std::shared_ptr<Shared> shared, int side)
    : shared_(std::move(shared)), side_(side) {}

void MemoryTransport::write(const uint8_t* data, size_t size) {
  std::lock_guard lock(shared_->mutex);
  if (shared_->lost) throw LinkLost("memory link: disconnected");
  auto& peer = shared_->input[1 - side_];
  peer.insert(peer.end(), data, data + size);
  shared_->changed.notify_all();
}

size_t MemoryTransport::read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) {
  std::unique_lock lock(shared_->mutex);
  auto& in = shared_->input[side_];
  shared_->clock.wait_for(shared_->changed, lock, timeout, [&] { return shared_->lost || !in.empty(); });
  // Bytes already delivered stay readable only while the link is up: an unplugged cable
  // loses what was in flight, which is what the session must cope with.
  if (shared_->lost) throw LinkLost("memory link: disconnected");
  const size_t n = std::min(max, in.size());
  for (size_t i = 0; i < n; ++i) {
    data[i] = in.front();
    in.pop_front();
  }
  return n;
}

void MemoryTransport::flush_input() {
  std::lock_guard lock(shared_->mutex);
  shared_->input[side_].clear();
}

void MemoryTransport::pulse_dtr(std::chrono::milliseconds) {
  std::lock_guard lock(shared_->mutex);
  if (shared_->lost) throw LinkLost("memory link: disconnected");
  shared_->input[side_].clear();
  ++shared_->dtr_pulses[side_];
}

int MemoryTransport::dtr_pulses() const {
  std::lock_guard lock(shared_->mutex);
  return shared_->dtr_pulses[side_];
}

void MemoryTransport::close() { disconnect(); }

void MemoryTransport::disconnect() {
  std::lock_guard lock(shared_->mutex);
  shared_->lost = true;
  shared_->changed.notify_all();
}

std::pair<std::unique_ptr<MemoryTransport>, std::unique_ptr<MemoryTransport>> make_memory_pair(Clock& clock) {
  auto shared = std::make_shared<MemoryTransport::Shared>(clock);
  return {std::make_unique<MemoryTransport>(shared, 0), std::make_unique<MemoryTransport>(shared, 1)};
}

}  // namespace atelier

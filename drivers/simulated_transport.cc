#include "drivers/simulated_transport.h"

#include <algorithm>

namespace atelier {

SimulatedTransport::SimulatedTransport(std::shared_ptr<SimulatedPeer> peer, FakeClock& clock)
    : peer_(std::move(peer)), clock_(clock) {}

void SimulatedTransport::lost() const { throw LinkLost("simulated link: disconnected"); }

void SimulatedTransport::take_from_peer() {
  const std::vector<uint8_t> out = peer_->take_output(clock_.now());
  pending_.insert(pending_.end(), out.begin(), out.end());
}

void SimulatedTransport::write(const uint8_t* data, size_t size) {
  if (closed_) lost();
  if (peer_->unplugged()) {
    // The cable is out: a write fails once the host has read what came before (until then
    // the other end is still open, as a pty being drained, and the bytes fall on the floor).
    if (pending_.empty()) lost();
    return;
  }
  peer_->receive(data, size, clock_.now());
}

size_t SimulatedTransport::read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = clock_.deadline_after(timeout);
  for (;;) {
    if (closed_) lost();
    take_from_peer();
    if (!pending_.empty()) {
      const size_t n = std::min(max, pending_.size());
      std::copy_n(pending_.begin(), n, data);
      pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n));
      return n;
    }
    if (peer_->unplugged()) lost();
    const Clock::time_point now = clock_.now();
    if (now >= deadline) return 0;
    Clock::time_point until = deadline;
    if (const auto next = peer_->next_event(); next && *next < until)
      until = std::max(*next, now + std::chrono::microseconds(1));  // always forward: no spinning in place
    clock_.advance_to(until);
  }
}

void SimulatedTransport::flush_input() {
  if (closed_) return;
  take_from_peer();
  pending_.clear();
}

void SimulatedTransport::pulse_dtr(std::chrono::milliseconds low) {
  if (closed_ || peer_->unplugged()) lost();
  peer_->dtr_pulse(clock_.now(), low);
  clock_.advance_to(clock_.now() + low);
  take_from_peer();
  pending_.clear();
}

void SimulatedTransport::close() { closed_ = true; }

}  // namespace atelier

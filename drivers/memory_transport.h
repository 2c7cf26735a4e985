// An in-memory Transport pair for tests: bytes written to one end are read from the other.
// disconnect() simulates pulling the cable: both ends then throw LinkLost from read/write.
// A read waits for bytes on the pair's clock (real_clock() unless given one): on a FakeClock its
// timeout passes only when the clock is moved, so a test decides when a read times out.
//
// Threading: each end may be read by one thread and written by another; disconnect() and
// close() may be called from any thread and wake blocked readers. Ownership: the two ends
// share the queues; either may outlive the other. The clock must outlive both.
#pragma once

#include <memory>
#include <utility>

#include "base/clock.h"
#include "drivers/transport.h"

namespace atelier {

class MemoryTransport : public Transport {
 public:
  struct Shared;  // queues, mutex, condition variable and clock shared by both ends
  MemoryTransport(std::shared_ptr<Shared> shared, int side);

  void write(const uint8_t* data, size_t size) override;
  size_t read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) override;
  void flush_input() override;
  // Discards this end's unread input and counts the pulse (dtr_pulses()); nothing is reset
  // at the other end, which is a test's own code. Returns at once.
  void pulse_dtr(std::chrono::milliseconds low) override;
  int dtr_pulses() const;
  // Closes this end: its blocked read wakes and throws LinkLost; the peer sees the link lost.
  void close() override;
  // Simulates unplugging: both ends throw LinkLost from now on.
  void disconnect();

 private:
  std::shared_ptr<Shared> shared_;
  int side_;  // 0 or 1: index of this end's input queue
};

// Two connected ends (first <-> second) whose reads wait on `clock`.
std::pair<std::unique_ptr<MemoryTransport>, std::unique_ptr<MemoryTransport>> make_memory_pair(
    Clock& clock = real_clock());

}  // namespace atelier

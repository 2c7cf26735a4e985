// A Transport for tests whose far end is a machine model (a scripted firmware, the knitting
// or laser emulator's model) run synchronously on a FakeClock: no second thread, no real time.
//
// write() hands the bytes to the peer at the clock's now(). read(timeout) returns what the peer
// has sent by now; when it has sent nothing, the read moves the clock to the peer's next event
// (or to the read's deadline, whichever comes first) and looks again, so a session and its peer
// advance in lock step and every timeout happens exactly where the protocol puts it. The
// reading thread is thus what moves the clock while it waits; other threads may wait on the
// same clock (they wake as it passes their deadlines) or move it too.
// A peer that pulls the cable (SimulatedPeer::unplugged()) first has everything it sent before
// read by the host, as a program that drains its pty before closing it; then reads and writes
// throw LinkLost. close() or disconnect() (from any thread) lose the link at once.
//
// Units: time points are the FakeClock's (Clock::time_point); read timeouts are milliseconds,
// as for every Transport.
// Threading: one thread reads and writes (the session's); close()/disconnect() from any thread.
// The peer is called only from that thread; a peer that tests inspect from other threads
// guards its own state. Ownership: the transport shares the peer (tests keep a pointer to look
// at it afterwards) and borrows the clock, which must outlive it.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "base/fake_clock.h"
#include "drivers/transport.h"

namespace atelier {

class SimulatedPeer {
 public:
  virtual ~SimulatedPeer() = default;
  // The host wrote these bytes at `now`.
  virtual void receive(const uint8_t* data, size_t size, Clock::time_point now) = 0;
  // Runs everything due by `now` and returns the bytes the peer has sent by then (taken).
  virtual std::vector<uint8_t> take_output(Clock::time_point now) = 0;
  // When the peer will next act on its own (after the `now` of its last call), or nullopt when
  // it only ever answers what it receives.
  virtual std::optional<Clock::time_point> next_event() const = 0;
  // True once the peer has pulled the cable.
  virtual bool unplugged() const { return false; }
  // The host dropped DTR at `now` for `low` (SimulatedTransport::pulse_dtr): a board wired
  // for it resets. Default: nothing happens (a board whose reset is not wired to DTR).
  virtual void dtr_pulse(Clock::time_point now, std::chrono::milliseconds low) {
    (void)now;
    (void)low;
  }
};

class SimulatedTransport : public Transport {
 public:
  SimulatedTransport(std::shared_ptr<SimulatedPeer> peer, FakeClock& clock);

  void write(const uint8_t* data, size_t size) override;
  size_t read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) override;
  void flush_input() override;
  // Tells the peer (SimulatedPeer::dtr_pulse), moves the clock on by `low`, and discards what
  // the peer sent until then.
  void pulse_dtr(std::chrono::milliseconds low) override;
  // Loses the link (both close() and disconnect()): reads and writes throw LinkLost, and what
  // the peer sent but the host did not read yet is gone.
  void close() override;
  void disconnect() { close(); }

  SimulatedPeer& peer() const { return *peer_; }

 private:
  void take_from_peer();
  [[noreturn]] void lost() const;

  std::shared_ptr<SimulatedPeer> peer_;
  FakeClock& clock_;
  std::vector<uint8_t> pending_;  // sent by the peer, not yet read by the host
  std::atomic<bool> closed_{false};
  bool unplugged_ = false;
};

}  // namespace atelier

// Test helper: a knitting machine behind a simulated link. Each open() is a freshly booted AYAB
// firmware model (tools/knit_emu/firmware.h) as the far end of a SimulatedTransport on the
// test's FakeClock, so a KnitDevice knits against it in simulated time, on its own worker
// thread, with no emulator process and no real time. Like atelier-knit-emu with --record, it
// records the needles of every knitted row, and numbers rows over its whole life across opens;
// the drop-after-row fault pulls the cable once the host has read the reqLine confirming that
// row, as the program does (a later open() is a replugged board: the replug delay is not
// modelled). Other faults are the model's own (Faults).
//
// Threading: open() and the peers run on the device's worker thread; recorded()/opened() may be
// called from any thread. `on_row` is called on the worker thread, with no lock held, right
// after a row is recorded (so a test can act at an exact point of the job). Ownership: the
// knitter and the clock must outlive every link it opened. Header-only.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "base/fake_clock.h"
#include "drivers/simulated_transport.h"
#include "tools/knit_emu/firmware.h"

namespace atelier::test {

class SimulatedKnitter {
 public:
  // `row_ms`: one carriage pass; `boot_ms`: input lost after the port opens (as the e2e
  // harness runs atelier-knit-emu).
  SimulatedKnitter(FakeClock& clock, int64_t row_ms, knit_emu::Faults faults = {}, int64_t boot_ms = 50)
      : clock_(clock), row_ms_(row_ms), boot_ms_(boot_ms), faults_(faults) {}

  std::unique_ptr<Transport> open() {
    int rows_before;
    {
      std::lock_guard lock(mu_);
      ++opened_;
      rows_before = static_cast<int>(rows_.size());
    }
    knit_emu::FirmwareOptions o;
    o.machine = ayab::MachineType::kh930;
    o.row_ms = row_ms_;
    o.boot_ms = boot_ms_;
    o.rows_before = rows_before;
    o.faults = faults_;
    return std::make_unique<SimulatedTransport>(std::make_shared<Peer>(*this, o, clock_.now()), clock_);
  }

  // The rows knitted so far, one needle string (0/1, working range) each.
  std::vector<std::string> recorded() const {
    std::lock_guard lock(mu_);
    return rows_;
  }
  int opened() const {
    std::lock_guard lock(mu_);
    return opened_;
  }

  std::function<void()> on_row;

 private:
  class Peer : public SimulatedPeer {
   public:
    Peer(SimulatedKnitter& machine, const knit_emu::FirmwareOptions& o, Clock::time_point now)
        : machine_(machine),
          epoch_(now),
          fw_(o, [this](const knit_emu::KnittedRow& row) { knitted(row); }, 0) {}

    void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
      fw_.advance_to(ms(now));
      fw_.receive(data, size);
    }
    std::vector<uint8_t> take_output(Clock::time_point now) override {
      fw_.advance_to(ms(now));
      std::vector<uint8_t> out = fw_.take_output();
      // The drop waits for the reqLine that confirms the row, so the host knows exactly what
      // was knitted (atelier-knit-emu does the same).
      for (size_t i = 0; drop_pending_ && i + 1 < out.size(); ++i)
        if (out[i] == 0xC0 && out[i + 1] == static_cast<uint8_t>(ayab::MsgId::reqLine)) unplugged_ = true;
      return out;
    }
    std::optional<Clock::time_point> next_event() const override {
      const auto next = fw_.next_event_ms();
      if (!next) return std::nullopt;
      return epoch_ + std::chrono::milliseconds(*next);
    }
    bool unplugged() const override { return unplugged_; }

   private:
    int64_t ms(Clock::time_point t) const {
      return std::chrono::duration_cast<std::chrono::milliseconds>(t - epoch_).count();
    }
    void knitted(const knit_emu::KnittedRow& row) {
      {
        std::lock_guard lock(machine_.mu_);
        machine_.rows_.push_back(row.needles);
      }
      const auto& drop = machine_.faults_.drop_after_row;
      if (drop && row.number == *drop) drop_pending_ = true;
      if (machine_.on_row) machine_.on_row();
    }

    SimulatedKnitter& machine_;
    const Clock::time_point epoch_;  // the firmware's clock 0
    knit_emu::Firmware fw_;
    bool drop_pending_ = false;
    bool unplugged_ = false;
  };

  FakeClock& clock_;
  const int64_t row_ms_, boot_ms_;
  const knit_emu::Faults faults_;
  mutable std::mutex mu_;
  std::vector<std::string> rows_;
  int opened_ = 0;
};

}  // namespace atelier::test

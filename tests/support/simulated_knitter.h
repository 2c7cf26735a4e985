// Test helper: a knitting machine behind a simulated link. Its AYAB firmware is the model of
// tools/knit_emu/firmware.h, the far end of a SimulatedTransport on the test's FakeClock, so a
// KnitDevice knits against it in simulated time, on its own worker thread, with no emulator
// process and no real time. Like atelier-knit-emu with --record, it records the needles of every
// knitted row, and numbers rows over its whole life across opens; the drop-after-row fault pulls
// the cable once the host has read the reqLine confirming that row, as the program does (a later
// open() is a replugged board: the replug delay is not modelled). Other faults are the model's
// own (Faults).
//
// Resets (how the board's reset is wired to DTR, `Wiring`): auto_reset, an Uno whose port was
// closed with HUPCL: every open() (DTR rises: the reset edge) and every pulse_dtr() boots a
// fresh firmware, which loses what arrives in its first boot_ms (50 ms here by default, against
// about 1 s on a real Uno and in atelier-knit-emu, to keep tests fast). A fresh firmware finds
// the carriage where the last one left it, and the row and cnfLine counts go on. on_pulse_only:
// the port was closed without dropping DTR (no HUPCL), so an open() finds the firmware as the
// last host left it, but a DTR pulse resets it. none (the no-dtr-reset fault, or
// Faults::dtr_reset false): nothing but power resets it. firmware() is the board's firmware
// now, for a test to drive or look at (no link may be in use meanwhile).
//
// Threading: open() and the peers run on the device's worker thread; recorded()/opened()/
// dtr_pulses() may be called from any thread. `on_row` is called on the worker thread, with no
// lock held, right after a row is recorded (so a test can act at an exact point of the job).
// Ownership: the knitter and the clock must outlive every link it opened. Header-only.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "base/fake_clock.h"
#include "drivers/simulated_transport.h"
#include "tools/knit_emu/firmware.h"

namespace atelier::test {

class SimulatedKnitter {
 public:
  enum class Wiring { auto_reset, on_pulse_only, none };

  // `row_ms`: one carriage pass; `boot_ms`: input lost after the port opens (as the e2e
  // harness runs atelier-knit-emu).
  SimulatedKnitter(FakeClock& clock, int64_t row_ms, knit_emu::Faults faults = {}, int64_t boot_ms = 50,
                   Wiring wiring = Wiring::auto_reset)
      : clock_(clock),
        row_ms_(row_ms),
        boot_ms_(boot_ms),
        faults_(faults),
        wiring_(faults.dtr_reset ? wiring : Wiring::none) {}

  std::unique_ptr<Transport> open() {
    {
      std::lock_guard lock(mu_);
      ++opened_;
    }
    if (!fw_ || wiring_ == Wiring::auto_reset) boot();
    return std::make_unique<SimulatedTransport>(std::make_shared<Peer>(*this), clock_);
  }

  // The rows knitted so far, one needle string (0/1, working range) each.
  std::vector<std::string> recorded() const {
    std::lock_guard lock(mu_);
    return rows_;
  }
  // The working range (first, last needle, 0-based) of each recorded row.
  std::vector<std::pair<int, int>> ranges() const {
    std::lock_guard lock(mu_);
    return ranges_;
  }
  int opened() const {
    std::lock_guard lock(mu_);
    return opened_;
  }
  int dtr_pulses() const {
    std::lock_guard lock(mu_);
    return dtr_pulses_;
  }
  knit_emu::Firmware& firmware() { return *fw_; }
  // Milliseconds on the firmware's clock at `t`.
  int64_t ms(Clock::time_point t) const {
    return std::chrono::duration_cast<std::chrono::milliseconds>(t - epoch_).count();
  }

  std::function<void()> on_row;

 private:
  class Peer : public SimulatedPeer {
   public:
    explicit Peer(SimulatedKnitter& machine) : machine_(machine) {}

    void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
      machine_.fw_->advance_to(machine_.ms(now));
      machine_.fw_->receive(data, size);
    }
    std::vector<uint8_t> take_output(Clock::time_point now) override {
      machine_.fw_->advance_to(machine_.ms(now));
      std::vector<uint8_t> out = machine_.fw_->take_output();
      // The drop waits for the reqLine that confirms the row, so the host knows exactly what
      // was knitted (atelier-knit-emu does the same).
      for (size_t i = 0; machine_.drop_pending_ && i + 1 < out.size(); ++i)
        if (out[i] == 0xC0 && out[i + 1] == static_cast<uint8_t>(ayab::MsgId::reqLine)) {
          unplugged_ = true;
          machine_.drop_pending_ = false;
        }
      return out;
    }
    std::optional<Clock::time_point> next_event() const override {
      const auto next = machine_.fw_->next_event_ms();
      if (!next) return std::nullopt;
      return machine_.epoch_ + std::chrono::milliseconds(*next);
    }
    bool unplugged() const override { return unplugged_; }
    void dtr_pulse(Clock::time_point, std::chrono::milliseconds) override {
      {
        std::lock_guard lock(machine_.mu_);
        ++machine_.dtr_pulses_;
      }
      if (machine_.wiring_ != Wiring::none) machine_.boot();
    }

   private:
    SimulatedKnitter& machine_;
    bool unplugged_ = false;
  };

  // A freshly booted firmware, its clock 0 now.
  void boot() {
    knit_emu::FirmwareOptions o;
    o.machine = ayab::MachineType::kh930;
    o.row_ms = row_ms_;
    o.boot_ms = boot_ms_;
    {
      std::lock_guard lock(mu_);
      o.rows_before = static_cast<int>(rows_.size());
    }
    o.faults = faults_;
    if (fw_) {
      o.cnf_lines_before = fw_->cnf_lines_received();
      o.carriage_position = fw_->carriage_position();
    }
    epoch_ = clock_.now();
    drop_pending_ = false;
    fw_ = std::make_unique<knit_emu::Firmware>(o, [this](const knit_emu::KnittedRow& row) { knitted(row); }, 0);
  }
  void knitted(const knit_emu::KnittedRow& row) {
    {
      std::lock_guard lock(mu_);
      rows_.push_back(row.needles);
      ranges_.emplace_back(row.start_needle, row.stop_needle);
    }
    const auto& drop = faults_.drop_after_row;
    if (drop && row.number == *drop) drop_pending_ = true;
    if (on_row) on_row();
  }

  FakeClock& clock_;
  const int64_t row_ms_, boot_ms_;
  const knit_emu::Faults faults_;
  const Wiring wiring_;
  // The board (worker thread): its firmware and the clock value of the firmware's 0.
  // `cnf_lines_`/`carriage_` carry the cnfLine count and the carriage over resets.
  std::unique_ptr<knit_emu::Firmware> fw_;
  Clock::time_point epoch_{};
  bool drop_pending_ = false;
  mutable std::mutex mu_;
  std::vector<std::string> rows_;
  std::vector<std::pair<int, int>> ranges_;
  int opened_ = 0;
  int dtr_pulses_ = 0;
};

}  // namespace atelier::test

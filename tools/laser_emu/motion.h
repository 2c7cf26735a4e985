// The motion side of the laser emulator: GRBL's 16-block planner (15 usable) and a stepper
// that moves the head through the blocks with GRBL's acceleration, with the laser output it
// drives.
//
// Planning is GRBL 1.1h's (algorithms/laser/motion_planner.h, the same model the time
// estimates use): per-axis rates and accelerations ($110-112, $120-122) along each block,
// junction speeds from the junction deviation $11, nominal-speed caps, and the exit speed
// planner_recalculate() allows over the blocks queued behind (the last one must be able to
// stop). A block that arrives while the head runs replans the running one from where it is,
// as GRBL's stepper picks up a new plan; a block pushed into an empty planner starts from rest.
// Each block runs as a trapezoid (accelerate, cruise, decelerate). A feed hold decelerates at
// the block's acceleration from the speed the head has (capped at the block's end); a resume
// starts the rest of the block from rest. Not modelled: the stepper's 8 ms segments.
// Laser rules (laser mode, DISABLE_LASER_DURING_HOLD as in stock 1.1h): a block's output is its
// (M3|M4, S) with S = 0 for G0; M4 power scales with actual/programmed speed, so it is off
// whenever the head stands still and lighter where the head accelerates; M3 keeps its last
// power while stopped (set by the last block or a spindle sync); the controller turns the beam
// off in a completed feed hold (set_hold_beam_off()); a stop (reset, alarm) turns it off.
// Outside laser mode ($32=0) M4 is a spindle like M3: not scaled, and it keeps running in a hold. The record gets one piece per
// phase of a block (accelerating, cruising, decelerating), so M4's power is exact per piece
// (the speed is linear in time within one).
// Positions: machine mm; block ends are quantised to whole steps ($100..$102) as GRBL does.
// Times: nanoseconds on the controller's steady clock; durations multiplied by `time_scale`.
// Segments and beam_off events go into the Record passed in (not owned; must outlive the Motion).
// Threading: one thread.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>

#include "algorithms/laser/motion_planner.h"
#include "tools/laser_emu/gcode.h"
#include "tools/laser_emu/record.h"
#include "tools/laser_emu/settings.h"

namespace atelier::laser_emu {

struct Block {
  Vec3 start{}, end{};  // mm
  double length = 0;    // mm
  double rate = 0;      // nominal speed, mm/min
  double accel = 0;     // acceleration limit along the block, mm/s^2
  laser::PlannerBlock plan;  // as plan_buffer_line() made it, with the overrides applied
  Spindle spindle = Spindle::off;
  double s = 0;         // 0: laser off for this block
  // For the feed/rapid overrides (plan_compute_profile_nominal_speed()): the programmed rate
  // (F, or the rapid rate for G0), the rapid rate along the block (the cap), and the entry
  // limit from the junction alone ((mm/s)^2; unknown above the 100 % nominal cap: taken as no
  // limit there, so an override above 100 % may take a corner faster than GRBL would).
  double programmed_mm_min = 0, rapid_mm_min = 0, junction_sqr = 0;
  bool rapid = false, no_override = false;  // no_override: a jog (PL_COND_FLAG_NO_FEED_OVERRIDE)
};

class Motion {
 public:
  static constexpr int kPlannerBlocks = 15;  // BLOCK_BUFFER_SIZE 16, one slot always free

  // `epoch_at_zero_s`: unix time (s) of clock value 0, for the record.
  Motion(const Settings& settings, double time_scale, Record& record, double epoch_at_zero_s);

  // Planner. plan_buffer_line(): false when the move has no steps (nothing queued).
  bool full() const { return static_cast<int>(queue_.size()) >= kPlannerBlocks; }
  int blocks() const { return static_cast<int>(queue_.size()); }
  bool push(const Vec3& target, double feed, bool rapid, bool inverse_time, Spindle spindle, double s,
            bool no_feed_override = false);
  // Overrides as fractions (1 = 100 %). Feed/rapid: every queued block's nominal speed is
  // recomputed and the running one replanned from its speed now (plan_update_velocity_profile_
  // parameters(), plan_cycle_reinitialize()); during a hold's deceleration they apply at the
  // resume. Spindle: the laser power (and reported S) scale by it, capped at $30.
  void set_feed_overrides(int64_t now, double feed, double rapid);
  void set_spindle_override(int64_t now, double factor);
  // Where the planner ends (mm, step-quantised) and where the head is now.
  Vec3 planner_position() const;
  Vec3 position() const;
  void set_position(const Vec3& mm);  // G-code position sync after a reset (head must be stopped)

  // Stepper. All calls take the current time; advance() must be called first.
  void advance(int64_t now);   // runs block ends / hold completion due by `now`
  std::optional<int64_t> next_event() const;
  bool running() const { return running_; }   // cycle active (Run, or Hold:1 decelerating)
  bool decelerating() const { return decel_; }
  void start(int64_t now);     // cycle start / resume: runs the queue (no-op when empty)
  void hold(int64_t now);      // feed hold: decelerate and stop
  void stop(int64_t now);      // reset / alarm: stop dead, beam off, planner flushed
  // Spindle sync from the G-code side (planner empty, head stopped): sets the output now.
  void set_spindle(int64_t now, Spindle spindle, double s);
  void set_hold_beam_off(int64_t now, bool off);  // spindle-stop override of a completed hold

  double speed_mm_min() const;     // realtime feed for status reports
  double laser_s() const;          // S currently applied (0 = beam off)
  Spindle laser_spindle() const;   // which mode the beam is on in (off when not emitting)

  // The piece under way as a segment ending at `now` (for snapshots); empty when none.
  std::optional<Segment> open_segment(int64_t now) const;

 private:
  struct Output {
    Spindle spindle = Spindle::off;
    double s = 0;
    double programmed_rate = 0, speed = 0;  // for M4 scaling, mm/min
  };
  double distance_at(int64_t t) const;    // along the current block
  // Plans the front block from d0_ on (its remaining length) at entry speed `entry_mm_min`,
  // from time `now`, with the blocks behind it in the queue.
  void profile_front(int64_t now, double entry_mm_min);
  // Ends of the front block's phases (accelerate, cruise, decelerate) on the clock.
  int64_t phase_end(int phase) const;
  double speed_at(int64_t t) const;       // mm/min
  Output output_at(int64_t t) const;
  double power_of(const Output& o) const;  // 0..1
  void close_piece(int64_t now);          // record the piece up to `now`
  void begin_piece(int64_t now);          // after a change: next piece, beam_off event
  void finish_block(int64_t t);
  void apply_overrides(size_t i);         // queue_[i]'s nominal speed and entry limit
  double epoch(int64_t t) const { return epoch0_ + static_cast<double>(t) * 1e-9; }

  const Settings& settings_;
  double time_scale_;
  Record& record_;
  double epoch0_;

  std::deque<Block> queue_;
  std::array<long, 3> planner_steps_{};  // end of the last queued block, in steps
  Vec3 head_{};                          // position when stopped / at the piece start

  bool running_ = false;
  int64_t now_ = 0;
  laser::BlockPlanner planner_;
  // Current block: distance d0 at time t0, then its profile over the rest (prof_), or a hold's
  // deceleration from decel_v0_.
  int64_t t0_ = 0;
  double d0_ = 0;
  laser::MoveProfile prof_;
  int phase_ = 0;          // 0 accelerating, 1 cruising, 2 decelerating
  bool decel_ = false;
  double decel_a_ = 0;     // mm/s^2
  double decel_v0_ = 0;    // mm/s when the hold began
  int64_t stop_t_ = 0;
  double stop_d_ = 0;

  double feed_ovr_ = 1, rapid_ovr_ = 1, spindle_ovr_ = 1;
  double last_nominal100_ = 0;  // the planner's previous nominal (mm/min, at 100 %) for junction_sqr

  Output idle_;            // laser output while no block runs
  bool hold_beam_off_ = false;

  // The piece being recorded.
  int64_t piece_t0_ = 0;
  Vec3 piece_p0_{};
  bool beam_was_on_ = false;
};

}  // namespace atelier::laser_emu

// GRBL 1.1h global settings ($$ / $n=v) for the laser emulator: the values, the "$$" listing in
// GRBL's order and number formats, and the checks settings.c makes when a value is stored.
//
// Defaults are a laser build: laser mode on ($32=1), S max $30=1000, soft limits on ($20=1)
// with homing off ($22=0, which real GRBL allows only as compiled-in defaults: typing $20=1
// without $22=1 answers error:10, as here). Machine space is 0..$130 x 0..$131 (mm), as GRBL built
// with HOMING_FORCE_SET_ORIGIN and homing directions X,Y set ($23=3); Z is -$132..0.
// Units: mm, mm/min (rates), mm/s^2 (accelerations), as GRBL reports them.
// Pure value type; not thread-safe.
#pragma once

#include <map>
#include <string>

namespace atelier::laser_emu {

class Settings {
 public:
  Settings(double work_w_mm, double work_h_mm);

  double get(int id) const;  // 0 for an unknown id
  // "$0=10\r\n$1=25\r\n..." (every setting, in GRBL's order and formats).
  std::string listing() const;
  // Stores "$<param>=<value>" like settings_store_global_setting(): returns a GRBL status code
  // (0 ok, 3 no such setting, 4 negative value, 6 step pulse < 3 us, 10 soft limits need homing).
  int store(double param, double value);
  // Back to the emulator's defaults ($RST=$).
  void restore_defaults();

  bool laser_mode() const { return get(32) != 0; }
  bool soft_limits() const { return get(20) != 0; }
  bool homing() const { return get(22) != 0; }
  double steps_per_mm(int axis) const { return get(100 + axis); }
  double max_rate(int axis) const { return get(110 + axis); }   // mm/min
  double accel(int axis) const { return get(120 + axis); }      // mm/s^2
  double max_travel(int axis) const { return get(130 + axis); }  // mm
  double s_max() const { return get(30); }
  int status_mask() const { return static_cast<int>(get(10)); }

 private:
  double work_w_, work_h_;
  std::map<int, double> values_;
};

}  // namespace atelier::laser_emu

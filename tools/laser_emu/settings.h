// GRBL 1.1h global settings ($$ / $n=v) for the laser emulator: the values, the "$$" listing in
// GRBL's order and number formats, and the checks settings.c makes when a value is stored.
//
// Compiled defaults (restore_defaults(), "$RST=$") are GRBL 1.1h's defaults.h DEFAULTS_GENERIC:
// laser mode off, soft limits and homing off, 200 mm travel, 500 mm/min, 10 mm/s^2. The
// emulator boots with what the owner of a diode laser stores over them (the constructor):
// laser mode $32=1, the work area as $130/$131, and the machine's motion ($100/$101=80
// steps/mm, $110/$111=6000 mm/min, $120/$121=500 mm/s^2). Soft limits stay off unless homing
// is on: store() refuses $20=1 while $22=0 (error:10), as settings.c does.
// Units: mm, mm/min (rates), mm/s^2 (accelerations), as GRBL reports them.
// Pure value type; not thread-safe.
#pragma once

#include <map>
#include <string>

namespace atelier::laser_emu {

class Settings {
 public:
  // The laser owner's EEPROM: compiled defaults plus the values above, work area in mm.
  Settings(double work_w_mm, double work_h_mm);

  double get(int id) const;  // 0 for an unknown id
  // "$0=10\r\n$1=25\r\n..." (every setting, in GRBL's order and formats).
  std::string listing() const;
  // Stores "$<param>=<value>" like settings_store_global_setting(): returns a GRBL status code
  // (0 ok, 3 no such setting, 4 negative value, 6 step pulse < 3 us, 10 soft limits need homing).
  int store(double param, double value);
  // Back to GRBL's compiled defaults ($RST=$ and $RST=*): laser mode off, 200 mm travel.
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
  std::map<int, double> values_;
};

}  // namespace atelier::laser_emu

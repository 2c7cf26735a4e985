// How a knitting job starts on the machine, as its own file says (the sidecar NAME.EXT.toml of
// a knit image, or a lace job file): `autostart = true` (knit as soon as the machine is free,
// without `atelierctl start`), `start_row = N` (begin at the Nth row knitted, counted from 1),
// `start_needle = "L20"` (the pattern's leftmost stitch on that needle). These keys are the
// machine's, not the conversion's: atelier-convert takes them out of a job layer before the
// kind's strict reader sees it, and atelierd reads them again when the job is started.
//
// A laser job's sidecar says how it runs in its `[laser]` table: `check_first = true|false`
// (dry run in GRBL check mode first, over the [laser] default of atelierd.toml) and
// `start_from = "bed"|"origin"|"here"` (where job (0,0) lands: the bed's front-left corner, the
// work zero G54 the operator set, or the head's position at start; drivers/grbl/machine_space.h).
// The conversion's reader accepts both in a sidecar and ignores them; atelierd reads them here.
//
// Needles are named as the knitter sees them: the bed's markings, L1..L100 left of the centre
// (L1 nearest it) and R1..R100 right of it on a 200-needle bed (KH-270: L56..R56), or a plain
// number counting needles from the bed's left end (1..200), as [[device]] start_needle does.
// Pure; thread-safe.
#pragma once

#include <optional>
#include <string>
#include <toml++/toml.h>

namespace atelier {

struct JobStart {
  std::optional<bool> autostart;
  std::optional<int> start_row;             // 1-based, in knitting order
  std::optional<std::string> start_needle;  // as written: "L20", "R5" or "20"
};

// Reads and removes the three keys from `layer` (a job's own file, `source`). ParamError
// "SOURCE:LINE: key 'start_row': ..." for a wrong type, a row below 1 or a needle name that
// is no needle of any bed.
JobStart take_job_start(toml::table& layer, const std::string& source);

struct LaserJobStart {
  std::optional<bool> check_first;
  std::optional<std::string> start_from;  // "bed", "origin" or "here"
};

// Reads and removes `check_first` and `start_from` from `layer`'s [laser] table (a laser job's
// sidecar, `source`); other keys are left for the conversion's strict reader, which refuses
// unknown ones. ParamError "SOURCE:LINE: key 'laser.start_from': ..." for a wrong value.
LaserJobStart take_laser_job_start(toml::table& layer, const std::string& source);

// The 0-based index of the needle `text` names on a bed of `needles` needles (200, or 112 for
// the KH-270), or nullopt with `problem` saying why ("L120 is not on the KH-930's bed (L100 to
// R100)" is the caller's; here: "needles are named L1..L100, R1..R100 or 1..200").
std::optional<int> parse_bed_needle(const std::string& text, int needles, std::string* problem = nullptr);
// The bed's marking of a 0-based needle: "L100".."L1", "R1".."R100" on a 200-needle bed.
std::string bed_needle_name(int index, int needles);

}  // namespace atelier

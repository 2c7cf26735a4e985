// Synthetic "scans" of pencil lines, one per grade 2H .. 8B, that the shipped pencil profiles
// are learned from (with learn_profile, the same code a user runs on a real scan).
//
// THESE ARE MODELLED, NOT SCANNED: no scans of real pencils were at hand when the profiles were
// made. The model follows what Meraj et al. 2008 report (section 3.2, figure 2, table 2): a dark
// centre whose grey level falls off in a bell shape across the line; graphite grain that is
// correlated along the stroke (the pencil rides the paper's tooth, so light and dark streaks run
// with the line); harder grades lighter, narrower and grainier (more paper shows through), soft
// grades dark and wide. The numbers in grade_models() are chosen to match those descriptions
// and common experience of pencils, not measured. For a pencil that looks like yours, scan a few
// of its lines and learn a profile with `atelier-convert pencil-profile SCAN.png OUT.toml`.
//
// Units: pixels (at roughly 300 dpi, where a soft pencil's line is ~7 px wide); grey levels
// 0 (black) .. 255 (white paper). Pure and reproducible: the same model, rows and seed give the
// same image on every run (cv::RNG, a portable generator, plus plain double arithmetic).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace atelier::pencil {

struct GradeModel {
  std::string name;           // "2H", ..., "8B"
  int centre_lo, centre_hi;   // grey levels of the line's centre (the hand's pressure varies
                              // slowly between them along the line)
  double width_px;            // full width of the graphite across the line
  double grain;               // share of the line where paper tooth shows through (0..1)
  double edge_grey;           // grey level at the line's edge, where it meets the paper
  double tooth_px;            // length (px) over which the grain stays correlated along the line
  double grain_amp;           // grey levels of graphite grain (standard deviation)
};

// The eight grades of the paper, lightest (2H) to darkest (8B). See the header comment: a model.
const std::vector<GradeModel>& grade_models();

// The model for `name` (exact, e.g. "6B"); nullptr if there is none.
const GradeModel* find_grade_model(const std::string& name);

// How the shipped profiles were made: reference_scan(model, kReferenceRows, kReferenceSeed).
inline constexpr int kReferenceRows = 300;
inline constexpr std::uint64_t kReferenceSeed = 1;
// Lines in one reference scan, side by side.
inline constexpr int kReferenceLines = 3;

// A grey image (CV_8UC1, paper = 255) of kReferenceLines vertical lines, `rows` px long, drawn
// by the model: each line's centre wanders by up to half a pixel (as a hand does); its tone
// falls off from the centre to edge_grey in a bell shape; each pixel gets grain from a field that
// is correlated along the line (an AR(1) process down each column with correlation length
// tooth_px); where that field is highest (the `grain` share of pixels) the paper shows through.
// Throws std::invalid_argument for rows < 1 or a model outside sane bounds (grey levels outside
// 0..255, centre_lo > centre_hi, width not in (0, 64], grain not in [0, 1), tooth_px <= 0).
cv::Mat reference_scan(const GradeModel& model, int rows, std::uint64_t seed);

}  // namespace atelier::pencil

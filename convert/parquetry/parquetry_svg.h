// Drawings of a parquetry plan: what the laser burns on each veneer sheet (cuts-<wood>.svg,
// and the same geometry for cuts.gcode) and how the pieces go together (assembly.svg).
//
// DECISION (paper 3.5): veneer is cut from the back, so a sheet lies FACE DOWN on the laser
// bed. Everything for the laser is therefore in the sheet's mirrored frame: x' = width - x,
// y' = y (sheet mm; the scan's top-left is the origin, y down). Piece IDs are engraved on the
// back and read normally in that mirrored view (they are laid out in it, not mirrored).
// The assembly is seen from the face: result mm, IDs readable there.
//
// SVG units are mm (width/height "…mm", viewBox in mm). Each piece is a
// <g id="piece-N" data-piece="N" data-sheet="ID"> holding its outline as a cubic Bezier path
// and its ID as single-stroke Hershey text (algorithms/laser/hershey_text.h): on the cut
// sheets the outline is red #ff0000 (the default cut layer) and the ID blue #0000ff (the
// default engrave layer). Thread-safe (no shared state); Hershey fonts are read once.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"
#include "algorithms/parquetry/plan.h"

namespace atelier {

inline constexpr const char* kParquetryCutColor = "#ff0000";
inline constexpr const char* kParquetryEngraveColor = "#0000ff";

// A piece on its sheet as the laser sees it (mirrored frame, sheet mm).
struct PieceCut {
  int id = 0;
  parquetry::Outline outline;        // the source outline, mirrored
  std::vector<laser::Path> id_text;  // the engraved ID: open single-stroke polylines
  double text_height_mm = 0;         // cap height of the ID
  double inscribed_mm = 0;           // diameter of the largest circle inside the piece
};

struct SheetCuts {
  std::string sheet_id;
  double width_mm = 0, height_mm = 0;  // the whole sheet (scan size / dpi)
  std::vector<PieceCut> pieces;        // the plan's pieces on this sheet, by id
};

// Size of a sheet in mm from its scan.
cv::Size2d sheet_size_mm(const parquetry::Sheet& sheet);

// The plan's pieces on `sheet`, mirrored, each with its ID centred on the piece's point
// farthest from its outline and sized to about 40% of its inscribed diameter (the whole ID
// stays inside that circle), at least 1.5 mm high.
SheetCuts sheet_cuts(const parquetry::Plan& plan, const parquetry::Sheet& sheet);

// cuts-<wood>.svg of one sheet: the outlines as curves, the ID strokes as polylines.
std::string cuts_svg(const SheetCuts& cuts);

// assembly.svg: the result, every piece's target outline in black and its ID (readable from
// the face), its wood and rotation in the piece's <title>.
std::string assembly_svg(const parquetry::Plan& plan);

}  // namespace atelier

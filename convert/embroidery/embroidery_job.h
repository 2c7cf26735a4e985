// The `embroidery` conversion (issue 6): an image -> an embroidery design (algorithms/
// embroidery/pipeline.h) and the stitch files a machine sews.
//
// Parameters: embroidery_params.h. User reference textures: `textures = FOLDER` holds, per
// style, <style>.png (long_short.png, satin.png, edge.png; colour, with the seams transparent
// in an alpha channel; any thread colour, it is recoloured) and optionally
// <style>.normal.png (tangent-space normal map of the same size). Their physical size is their
// pixel size at `texture_dpi`. A style without a file keeps the procedural texture.
//
// Writes into the output folder, each file atomically (output_files.h):
//   design.dst    Tajima DST (convert/embroidery/dst_writer.h), label = the input's stem
//   design.exp    Melco EXP (exp_writer.h)
//   design.pes    Brother PES v1 with its PEC section (pes_writer.h)
//   design.jef    Janome JEF (jef_writer.h)
//   preview.png   the synthesized embroidery, at the working resolution
//   stitches.png  the stitch plan drawn as thread (algorithms/embroidery/stitch_render.h), in
//                 the preview's frame
//   threads.pdf   the operator's colour sheet (thread_sheet.h)
//   normal.png    its tangent-space normal map
//   regions.png   the stitch-style labels (paper Fig. 3): long-short blue, satin green, edge
//                 red, not sewn white; region borders dark
//   report.json   size_mm, px_per_mm, colours (per thread: rgb, stitches), regions per style
//                 (count, area_mm2), components and those forced to long-short, stitches,
//                 jumps, trims, color_changes, extent of the stitches in mm, hoop_mm, textures
//                 used, params
// Thread-safe per request (no shared state).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/embroidery/textures.h"
#include "convert/convert.h"

namespace atelier {

// The stitch files: design.<format>, one per format written. A file-drop device delivers the
// default ones when its `formats` names none (the commercial machines' formats, as before PES
// and JEF were written).
inline constexpr const char* kDesignStem = "design";
inline const std::vector<std::string_view>& stitch_formats() {
  static const std::vector<std::string_view> formats{"dst", "exp", "pes", "jef"};
  return formats;
}
inline const std::vector<std::string_view>& default_stitch_formats() {
  static const std::vector<std::string_view> formats{"dst", "exp"};
  return formats;
}

// Throws ParamError (parameters) and ConvertError (unreadable input or textures, a design
// larger than the hoop, output files).
ConvertResult convert_embroidery(const ConvertRequest& request);

// The procedural textures with the styles found in `folder` replaced (see above), and per
// style where it came from (the file, or "procedural"). Throws ConvertError naming the file
// for a missing folder or an unreadable or inconsistent texture.
struct LoadedTextures {
  embroidery::TextureSet set;
  std::string sources[embroidery::kStyleCount];
};
LoadedTextures load_textures(const PathAccess& access, const std::filesystem::path& folder, double dpi,
                             const ImageLimits& limits);

}  // namespace atelier

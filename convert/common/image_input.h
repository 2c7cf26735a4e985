// Reading a user's image safely: size and pixel limits are checked from the file header
// before anything is decoded, and every failure names the file and the problem.
//
// Thread-safe (no shared state). Errors are ConvertError (convert_error.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "convert/common/job_paths.h"

namespace atelier {

struct ImageLimits {
  uint64_t max_file_bytes = 209715200;  // bytes
  uint64_t max_pixels = 40000000;       // width * height
};

struct ImageHeader {
  std::string format;  // "png", "jpeg", "bmp", "webp", "tiff", "pnm"
  uint64_t width = 0;
  uint64_t height = 0;
};

// Reads only the header. Throws ConvertError("FILE: ...") for an empty file, an unknown
// or unsupported format (e.g. a text file named .png), or a header without dimensions.
ImageHeader probe_image(const std::filesystem::path& file);

// Checks the file size, probes the header against `limits`, then decodes with OpenCV
// (IMREAD_UNCHANGED: alpha kept). Throws ConvertError naming the file for every failure,
// including truncated or corrupt data that the decoder rejects.
cv::Mat load_image(const std::filesystem::path& file, const ImageLimits& limits);

// The same for a file a parameter names, opened through `access` (job_paths.h: confined to the
// spool when a job named it). Messages start with access.prefix(file) ("SIDECAR: key 'K': FILE: ").
cv::Mat load_image(const PathAccess& access, const std::filesystem::path& file, const ImageLimits& limits);

// The checks and decoding of load_image on bytes already read; every message starts with
// `prefix` (which names the file).
cv::Mat decode_image(const std::vector<unsigned char>& data, const std::string& prefix,
                     const ImageLimits& limits);

// The image with 8-bit pixels (the same data when it already has them): decoders give 16-bit
// PNGs and TIFFs as 0..65535 (scaled by 1/257) and float TIFFs as 0..1 (scaled by 255); other
// depths are converted as they are (saturated).
cv::Mat to_8bit(const cv::Mat& image);

}  // namespace atelier

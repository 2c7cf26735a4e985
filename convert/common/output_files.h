// Writing a conversion's outputs: each file is written beside its target under a ".tmp" name
// and renamed into place, so a reader (or a crash) never sees half a file. Errors are
// ConvertErrors naming the file. Thread-safe (no shared state).
#pragma once

#include <cstddef>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "convert/common/convert_error.h"

namespace atelier {

void write_output(const std::filesystem::path& file, const char* data, size_t size);
void write_output(const std::filesystem::path& file, const std::string& content);
// Encodes `image` (8-bit grey or BGR) as PNG.
void write_output_png(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace atelier

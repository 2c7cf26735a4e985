#include "convert/common/image_input.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <system_error>
#include <vector>

#include "convert/convert.h"
#include "convert/common/display_text.h"
#include "convert/common/image_signature.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& file, const std::string& problem) {
  throw ConvertError(display_name(file) + ": " + problem);
}

// Refuses anything that is not a regular file (directories, devices, dangling links) before
// opening it, so a FIFO or /dev/zero can neither block nor exhaust memory.
uint64_t regular_file_size(const fs::path& file) {
  std::error_code ec;
  fs::file_status st = fs::status(file, ec);
  if (ec || !fs::exists(st)) fail(file, "file not found");
  if (fs::is_directory(st)) fail(file, "is a directory, not an image");
  if (!fs::is_regular_file(st)) fail(file, "not a regular file");
  uint64_t size = fs::file_size(file, ec);
  if (ec) fail(file, "cannot read file size: " + ec.message());
  return size;
}

// Reads the first `limit` bytes at most; the caller compares the result's size with the limit.
std::vector<unsigned char> read_prefix(const fs::path& file, uint64_t limit) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open file: " + std::string(std::strerror(errno)));
  std::vector<unsigned char> data;
  unsigned char chunk[1 << 16];
  while (data.size() < limit) {
    uint64_t want = std::min<uint64_t>(sizeof chunk, limit - data.size());
    in.read(reinterpret_cast<char*>(chunk), static_cast<std::streamsize>(want));
    std::streamsize got = in.gcount();
    if (got <= 0) break;
    data.insert(data.end(), chunk, chunk + got);
  }
  if (in.bad()) fail(file, "read error");
  return data;
}

// Reads the file from disk piece by piece, so probing a large file touches only its header.
class FileBytes : public ByteSource {
 public:
  explicit FileBytes(const fs::path& file) : in_(file, std::ios::binary) {
    if (!in_) fail(file, "cannot open file: " + std::string(std::strerror(errno)));
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(in_.tellg());
  }
  uint64_t size() const override { return size_; }
  size_t read(uint64_t offset, unsigned char* out, size_t n) override {
    if (offset >= size_) return 0;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
    return static_cast<size_t>(in_.gcount());
  }

 private:
  std::ifstream in_;
  uint64_t size_ = 0;
};

std::string size_text(uint64_t w, uint64_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

}  // namespace

ImageHeader probe_image(const fs::path& file) {
  regular_file_size(file);
  FileBytes bytes(file);
  try {
    return probe_header(bytes);
  } catch (const SignatureError& e) {
    fail(file, e.what());
  }
}

cv::Mat load_image(const fs::path& file, const ImageLimits& limits) {
  uint64_t size = regular_file_size(file);
  if (size > limits.max_file_bytes) {
    fail(file, "file is " + std::to_string(size) + " bytes, over the limit of " +
                   std::to_string(limits.max_file_bytes) + " bytes");
  }
  // One read of the whole file: the header check, the truncation check and the decoder all
  // see the same bytes, even if the file changes meanwhile. +1 detects a file that grew.
  std::vector<unsigned char> data = read_prefix(file, limits.max_file_bytes + 1);
  if (data.size() > limits.max_file_bytes) {
    fail(file, "file grew over the limit of " + std::to_string(limits.max_file_bytes) +
                   " bytes while being read");
  }
  return decode_image(data, display_name(file) + ": ", limits);
}

cv::Mat load_image(const PathAccess& access, const fs::path& file, const ImageLimits& limits) {
  const std::vector<unsigned char> data = access.read_file(file, limits.max_file_bytes);
  return decode_image(data, access.prefix(file), limits);
}

cv::Mat decode_image(const std::vector<unsigned char>& data, const std::string& prefix,
                     const ImageLimits& limits) {
  auto fail = [&prefix](const std::string& problem) -> void { throw ConvertError(prefix + problem); };
  if (data.size() > limits.max_file_bytes) {
    fail("file is " + std::to_string(data.size()) + " bytes, over the limit of " +
         std::to_string(limits.max_file_bytes) + " bytes");
  }
  MemoryBytes bytes(data);
  ImageHeader header;
  try {
    header = probe_header(bytes);
  } catch (const SignatureError& e) {
    fail(e.what());
  }
  if (header.width > limits.max_pixels || header.height > limits.max_pixels ||
      header.width * header.height > limits.max_pixels) {
    fail("image is " + size_text(header.width, header.height) + " = " +
         std::to_string(header.width * header.height) + " pixels, over the limit of " +
         std::to_string(limits.max_pixels) + " pixels");
  }
  if (std::optional<std::string> problem = check_complete(header.format, bytes)) fail(*problem);
  // JPEG has no alpha: IMREAD_COLOR applies the EXIF orientation a phone photo relies on.
  int flags = header.format == "jpeg" ? cv::IMREAD_COLOR : cv::IMREAD_UNCHANGED;
  cv::Mat image;
  try {
    image = cv::imdecode(data, flags);
  } catch (const cv::Exception& e) {
    // OpenCV's message names its own source line, never the file's bytes.
    fail("cannot decode " + header.format + " data: " + display_value(e.err, 120));
  }
  if (image.empty()) fail("cannot decode " + header.format + " data (corrupt file)");
  return image;
}

cv::Mat to_8bit(const cv::Mat& image) {
  if (image.depth() == CV_8U) return image;
  const bool floating = image.depth() == CV_32F || image.depth() == CV_64F;
  cv::Mat out;
  image.convertTo(out, CV_8U, image.depth() == CV_16U ? 1.0 / 257.0 : floating ? 255.0 : 1.0);
  return out;
}

}  // namespace atelier

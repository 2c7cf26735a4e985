#include "convert/common/output_files.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <vector>

namespace fs = std::filesystem;

namespace atelier {

void write_output(const fs::path& file, const char* data, size_t size) {
  fs::path tmp = file;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) out.write(data, static_cast<std::streamsize>(size));
    if (out) out.close();
    if (!out) {
      const int err = errno;
      std::error_code ignored;
      fs::remove(tmp, ignored);  // nothing half-written is left behind
      throw ConvertError(file.filename().string() + ": cannot write: " + std::strerror(err));
    }
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw ConvertError(file.filename().string() + ": cannot write: " + ec.message());
  }
}

void write_output(const fs::path& file, const std::string& content) {
  write_output(file, content.data(), content.size());
}

void write_output_png(const fs::path& file, const cv::Mat& image) {
  std::vector<uchar> png;
  try {
    if (!cv::imencode(".png", image, png)) throw ConvertError(file.filename().string() + ": cannot encode PNG");
  } catch (const cv::Exception& e) {
    throw ConvertError(file.filename().string() + ": cannot encode PNG: " + e.err);
  }
  write_output(file, reinterpret_cast<const char*>(png.data()), png.size());
}

}  // namespace atelier

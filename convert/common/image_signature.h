// Image file headers parsed by hand: format signature and pixel size, read before any
// decoder runs (so a 100000x100000 PNG is refused without allocating), and a completeness
// check for truncated files (OpenCV's JPEG decoder returns a half-grey picture for them).
//
// Internal to convert/common (image_input.cc uses it). Thread-safe: no shared state.
// Errors are SignatureError with a message that lacks the file name; the caller adds it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"
#include "convert/common/image_input.h"

namespace atelier {

class SignatureError : public BadInput {
 public:
  using BadInput::BadInput;
};

// Random access to a file's bytes. read() returns how many bytes it copied (short at the end).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual uint64_t size() const = 0;
  virtual size_t read(uint64_t offset, unsigned char* out, size_t n) = 0;
};

// A view of bytes held by the caller (who keeps them alive).
class MemoryBytes : public ByteSource {
 public:
  explicit MemoryBytes(const std::vector<unsigned char>& data) : data_(data) {}
  uint64_t size() const override { return data_.size(); }
  size_t read(uint64_t offset, unsigned char* out, size_t n) override;

 private:
  const std::vector<unsigned char>& data_;
};

// Format and size from the header: PNG IHDR, JPEG SOFn, BMP info header, WebP VP8/VP8L/VP8X,
// TIFF first IFD, PNM P1-P6. Throws SignatureError for an empty file, an unknown format or a
// header that ends before it gives the size (or gives a zero size).
ImageHeader probe_header(ByteSource& bytes);

// A problem text ("truncated: ...") when the file's structure ends early: a JPEG without its
// end-of-image marker after the scan data, a PNG without IEND, a BMP/WebP shorter than its
// header says. nullopt when complete (or the format has no cheap check: TIFF, PNM).
std::optional<std::string> check_complete(const std::string& format, ByteSource& bytes);

}  // namespace atelier

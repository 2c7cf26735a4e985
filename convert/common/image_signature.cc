#include "convert/common/image_signature.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace atelier {
namespace {

// Buffered byte access over a ByteSource: 64 KiB windows, so walking a JPEG's scan data byte
// by byte stays cheap for files on disk as well as in memory.
class Cursor {
 public:
  explicit Cursor(ByteSource& src) : src_(src), size_(src.size()) {}
  uint64_t size() const { return size_; }
  bool has(uint64_t offset, uint64_t n = 1) const { return offset + n <= size_ && offset + n >= n; }
  // Caller checks has() first.
  unsigned char at(uint64_t offset) {
    if (offset < base_ || offset >= base_ + len_) {
      base_ = offset;
      len_ = src_.read(offset, buf_.data(), buf_.size());
      if (len_ == 0) throw SignatureError("read error");
    }
    return buf_[offset - base_];
  }
  uint32_t be16(uint64_t o) { return (uint32_t{at(o)} << 8) | at(o + 1); }
  uint32_t le16(uint64_t o) { return uint32_t{at(o)} | (uint32_t{at(o + 1)} << 8); }
  uint32_t be32(uint64_t o) { return (be16(o) << 16) | be16(o + 2); }
  uint32_t le32(uint64_t o) { return le16(o) | (le16(o + 2) << 16); }
  uint32_t le24(uint64_t o) { return le16(o) | (uint32_t{at(o + 2)} << 16); }
  bool matches(uint64_t o, const char* text) {
    size_t n = std::strlen(text);
    if (!has(o, n)) return false;
    for (size_t i = 0; i < n; ++i)
      if (at(o + i) != static_cast<unsigned char>(text[i])) return false;
    return true;
  }

 private:
  ByteSource& src_;
  uint64_t size_;
  std::array<unsigned char, 1 << 16> buf_{};
  uint64_t base_ = 0;
  size_t len_ = 0;
};

const char* const kNoSize = "header ends before the image size (truncated file)";

void need(Cursor& c, uint64_t offset, uint64_t n) {
  if (!c.has(offset, n)) throw SignatureError(kNoSize);
}

ImageHeader sized(const char* format, uint64_t w, uint64_t h) {
  if (w == 0 || h == 0) {
    throw SignatureError(std::string(format) + " header gives no image size (" +
                         std::to_string(w) + "x" + std::to_string(h) + ")");
  }
  return ImageHeader{format, w, h};
}

bool is_sof(unsigned m) {
  return m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
}
bool has_no_length(unsigned m) { return m == 0x01 || m == 0xD8 || (m >= 0xD0 && m <= 0xD7); }

// Reads the marker at `o` (skipping fill bytes); returns the marker code and moves `o` past it.
// Returns 0 when the data is not at a marker.
unsigned read_marker(Cursor& c, uint64_t& o) {
  if (!c.has(o) || c.at(o) != 0xFF) return 0;
  while (c.has(o) && c.at(o) == 0xFF) ++o;
  if (!c.has(o)) return 0;
  return c.at(o++);
}

ImageHeader probe_jpeg(Cursor& c) {
  uint64_t o = 2;
  while (true) {
    if (!c.has(o)) throw SignatureError(kNoSize);
    unsigned m = read_marker(c, o);
    if (m == 0) throw SignatureError("corrupt JPEG: expected a marker at byte " + std::to_string(o));
    if (has_no_length(m)) continue;
    if (m == 0xD9 || m == 0xDA) throw SignatureError("JPEG has no frame header (image size missing)");
    need(c, o, 2);
    uint32_t len = c.be16(o);
    if (len < 2) throw SignatureError("corrupt JPEG: segment length " + std::to_string(len));
    if (is_sof(m)) {
      need(c, o, 7);
      return sized("jpeg", c.be16(o + 5), c.be16(o + 3));
    }
    o += len;
  }
}

ImageHeader probe_png(Cursor& c) {
  need(c, 8, 16);
  if (!c.matches(12, "IHDR")) throw SignatureError("corrupt PNG: first chunk is not IHDR");
  return sized("png", c.be32(16), c.be32(20));
}

ImageHeader probe_bmp(Cursor& c) {
  need(c, 14, 4);
  uint32_t dib = c.le32(14);
  if (dib == 12) {
    need(c, 18, 4);
    return sized("bmp", c.le16(18), c.le16(20));
  }
  if (dib < 40) throw SignatureError("corrupt BMP: info header of " + std::to_string(dib) + " bytes");
  need(c, 18, 8);
  auto w = static_cast<int32_t>(c.le32(18));
  auto h = static_cast<int32_t>(c.le32(22));
  if (w < 0) throw SignatureError("corrupt BMP: negative width");
  int64_t ah = h < 0 ? -int64_t{h} : int64_t{h};  // negative height = top-down rows
  return sized("bmp", static_cast<uint64_t>(w), static_cast<uint64_t>(ah));
}

ImageHeader probe_webp(Cursor& c) {
  need(c, 12, 8);
  if (c.matches(12, "VP8 ")) {
    need(c, 20, 10);
    if (c.at(23) != 0x9D || c.at(24) != 0x01 || c.at(25) != 0x2A)
      throw SignatureError("corrupt WebP: bad VP8 start code");
    return sized("webp", c.le16(26) & 0x3FFF, c.le16(28) & 0x3FFF);
  }
  if (c.matches(12, "VP8L")) {
    need(c, 20, 5);
    if (c.at(20) != 0x2F) throw SignatureError("corrupt WebP: bad VP8L signature");
    uint32_t bits = c.le32(21);
    return sized("webp", (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1);
  }
  if (c.matches(12, "VP8X")) {
    need(c, 20, 10);
    return sized("webp", c.le24(24) + 1, c.le24(27) + 1);
  }
  throw SignatureError("WebP file without a VP8, VP8L or VP8X chunk (image size missing)");
}

ImageHeader probe_tiff(Cursor& c) {
  bool le = c.at(0) == 'I';
  auto u16 = [&](uint64_t o) { return le ? c.le16(o) : c.be16(o); };
  auto u32 = [&](uint64_t o) { return le ? c.le32(o) : c.be32(o); };
  need(c, 0, 8);
  if (u16(2) == 43) throw SignatureError("BigTIFF is not supported");
  uint64_t ifd = u32(4);
  need(c, ifd, 2);
  uint32_t count = u16(ifd);
  uint64_t width = 0, height = 0;
  for (uint32_t i = 0; i < count; ++i) {
    uint64_t e = ifd + 2 + uint64_t{i} * 12;
    need(c, e, 12);
    uint32_t tag = u16(e), type = u16(e + 2);
    if (tag != 256 && tag != 257) continue;
    uint64_t v = type == 3 ? u16(e + 8) : type == 4 ? u32(e + 8) : 0;
    if (type != 3 && type != 4) throw SignatureError("corrupt TIFF: image size of type " + std::to_string(type));
    (tag == 256 ? width : height) = v;
  }
  return sized("tiff", width, height);
}

ImageHeader probe_pnm(Cursor& c) {
  uint64_t o = 2;
  auto number = [&]() -> uint64_t {
    while (true) {  // whitespace and comments
      if (!c.has(o)) throw SignatureError(kNoSize);
      unsigned char ch = c.at(o);
      if (ch == '#') {
        while (c.has(o) && c.at(o) != '\n') ++o;
      } else if (ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n') {
        ++o;
      } else {
        break;
      }
    }
    uint64_t v = 0;
    int digits = 0;
    while (c.has(o) && c.at(o) >= '0' && c.at(o) <= '9') {
      if (++digits > 12) throw SignatureError("corrupt PNM: size too long");
      v = v * 10 + (c.at(o++) - '0');
    }
    if (digits == 0) throw SignatureError("corrupt PNM: expected the image size");
    return v;
  };
  uint64_t w = number();
  uint64_t h = number();
  return sized("pnm", w, h);
}

std::optional<std::string> jpeg_complete(Cursor& c) {
  uint64_t o = 2;
  while (true) {
    if (!c.has(o)) return "truncated JPEG: no end-of-image marker";
    unsigned m = read_marker(c, o);
    if (m == 0) return "corrupt JPEG: expected a marker at byte " + std::to_string(o);
    if (m == 0xD9) return std::nullopt;
    if (has_no_length(m)) continue;
    if (!c.has(o, 2)) return "truncated JPEG: segment header cut off";
    uint64_t len = c.be16(o);
    o += len;
    if (m != 0xDA) continue;
    // Entropy-coded data: 0xFF is followed by 0x00 (stuffing), a restart marker or fill
    // bytes; any other marker ends the scan.
    while (true) {
      while (c.has(o) && c.at(o) != 0xFF) ++o;
      if (!c.has(o + 1)) return "truncated JPEG: image data ends without the end-of-image marker";
      unsigned next = c.at(o + 1);
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        o += 2;
      } else if (next == 0xFF) {
        ++o;
      } else {
        break;  // o is at the marker
      }
    }
  }
}

std::optional<std::string> png_complete(Cursor& c) {
  uint64_t o = 8;
  while (true) {
    if (!c.has(o, 8)) return "truncated PNG: no IEND chunk";
    uint32_t len = c.be32(o);
    if (len > 0x7FFFFFFFu) return "corrupt PNG: chunk length " + std::to_string(len);
    if (c.matches(o + 4, "IEND")) return std::nullopt;
    o += 12 + uint64_t{len};
  }
}

}  // namespace

size_t MemoryBytes::read(uint64_t offset, unsigned char* out, size_t n) {
  if (offset >= data_.size()) return 0;
  size_t k = std::min<uint64_t>(n, data_.size() - offset);
  std::memcpy(out, data_.data() + offset, k);
  return k;
}

ImageHeader probe_header(ByteSource& bytes) {
  Cursor c(bytes);
  if (c.size() == 0) throw SignatureError("empty file");
  if (c.has(0, 3) && c.at(0) == 0xFF && c.at(1) == 0xD8 && c.at(2) == 0xFF) return probe_jpeg(c);
  if (c.matches(0, "\x89PNG\r\n\x1a\n")) return probe_png(c);
  if (c.matches(0, "BM")) return probe_bmp(c);
  if (c.matches(0, "RIFF") && c.matches(8, "WEBP")) return probe_webp(c);
  if (c.has(0, 4)) {
    unsigned b0 = c.at(0), b1 = c.at(1), b2 = c.at(2), b3 = c.at(3);
    bool tiff_le = b0 == 'I' && b1 == 'I' && (b2 == 42 || b2 == 43) && b3 == 0;
    bool tiff_be = b0 == 'M' && b1 == 'M' && b2 == 0 && (b3 == 42 || b3 == 43);
    if (tiff_le || tiff_be) return probe_tiff(c);
  }
  if (c.has(0, 2) && c.at(0) == 'P' && c.at(1) >= '1' && c.at(1) <= '6') return probe_pnm(c);
  throw SignatureError("not an image (no PNG, JPEG, BMP, WebP, TIFF or PNM signature)");
}

std::optional<std::string> check_complete(const std::string& format, ByteSource& bytes) {
  Cursor c(bytes);
  if (format == "jpeg") return jpeg_complete(c);
  if (format == "png") return png_complete(c);
  if (format == "bmp") {
    uint32_t declared = c.has(2, 4) ? c.le32(2) : 0;  // 0: writer left it out
    if (declared != 0 && c.size() < declared)
      return "truncated BMP: " + std::to_string(c.size()) + " of " + std::to_string(declared) + " bytes";
  }
  if (format == "webp") {
    uint64_t declared = uint64_t{c.le32(4)} + 8;
    if (c.size() < declared)
      return "truncated WebP: " + std::to_string(c.size()) + " of " + std::to_string(declared) + " bytes";
  }
  return std::nullopt;
}

}  // namespace atelier

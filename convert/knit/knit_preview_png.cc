#include "convert/knit/knit_preview_png.h"

#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <vector>

namespace atelier {
namespace {

// PNG's CRC-32 (ISO 3309), table-driven.
const std::array<uint32_t, 256>& crc_table() {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  return table;
}

uint32_t crc32(const uint8_t* p, size_t n, uint32_t crc = 0) {
  const auto& t = crc_table();
  crc = ~crc;
  for (size_t i = 0; i < n; ++i) crc = t[(crc ^ p[i]) & 0xff] ^ (crc >> 8);
  return ~crc;
}

// zlib's Adler-32, updated per scanline (sums reduced every 5552 bytes, as zlib does).
struct Adler {
  uint32_t a = 1, b = 0;
  void update(const uint8_t* p, size_t n) {
    while (n > 0) {
      const size_t k = std::min<size_t>(n, 5552);
      for (size_t i = 0; i < k; ++i) {
        a += p[i];
        b += a;
      }
      a %= 65521;
      b %= 65521;
      p += k;
      n -= k;
    }
  }
  uint32_t value() const { return (b << 16) | a; }
};

// Deflate (RFC 1951) with the fixed Huffman codes, bits packed LSB first.
class FixedDeflate {
 public:
  explicit FixedDeflate(std::string& out) : out_(out) { put(1, 1), put(1, 2); }  // BFINAL, BTYPE=01

  void literal(uint8_t v) { symbol(v); }

  // `n` bytes equal to those `d` back (1 <= d <= 32768), as matches of 3..258 bytes; a
  // remainder under 3 is sent as literals from `bytes` (the n bytes themselves).
  void copy(size_t n, int d, const uint8_t* bytes) {
    size_t done = 0;
    while (n - done >= 3) {
      size_t len = std::min<size_t>(n - done, 258);
      if (n - done - len > 0 && n - done - len < 3) len -= 3;  // keep the tail matchable
      match(static_cast<int>(len), d);
      done += len;
    }
    for (; done < n; ++done) literal(bytes[done]);
  }

  void finish() {
    symbol(256);  // end of block
    if (nbits_ > 0) out_.push_back(static_cast<char>(acc_ & 0xff));
    acc_ = 0;
    nbits_ = 0;
  }

 private:
  void put(uint32_t bits, int n) {  // n <= 24
    acc_ |= static_cast<uint64_t>(bits) << nbits_;
    nbits_ += n;
    while (nbits_ >= 8) {
      out_.push_back(static_cast<char>(acc_ & 0xff));
      acc_ >>= 8;
      nbits_ -= 8;
    }
  }
  // Huffman codes are sent most significant bit first: reversed once into tables.
  static uint32_t reversed(uint32_t c, int n) {
    uint32_t r = 0;
    for (int i = 0; i < n; ++i) r |= ((c >> i) & 1u) << (n - 1 - i);
    return r;
  }
  struct Code {
    uint32_t bits;
    int n;
  };
  struct Tables {
    Code sym[288];
    Code len[259];   // length 3..258: symbol code and extra bits, merged
    Code dist[32769];  // distance 1..32768: code and extra bits, merged
  };
  static const Tables& tables() {
    static const Tables* t = [] {
      static constexpr int kLenBase[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                           31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
      static constexpr int kLenExtra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                            2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
      static constexpr int kDistBase[30] = {1,    2,    3,    4,    5,    7,     9,     13,    17,  25,
                                            33,   49,   65,   97,   129,  193,   257,   385,   513, 769,
                                            1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
      static constexpr int kDistExtra[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                             6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
      auto* t = new Tables{};
      for (int s = 0; s < 288; ++s) {
        if (s < 144) t->sym[s] = {reversed(0x30 + s, 8), 8};
        else if (s < 256) t->sym[s] = {reversed(0x190 + (s - 144), 9), 9};
        else if (s < 280) t->sym[s] = {reversed(s - 256, 7), 7};
        else t->sym[s] = {reversed(0xc0 + (s - 280), 8), 8};
      }
      for (int len = 3; len <= 258; ++len) {
        int l = 28;
        while (kLenBase[l] > len) --l;
        const Code c = t->sym[257 + l];
        t->len[len] = {c.bits | (static_cast<uint32_t>(len - kLenBase[l]) << c.n), c.n + kLenExtra[l]};
      }
      for (int dist = 1; dist <= 32768; ++dist) {
        int d = 29;
        while (kDistBase[d] > dist) --d;
        t->dist[dist] = {reversed(static_cast<uint32_t>(d), 5) | (static_cast<uint32_t>(dist - kDistBase[d]) << 5),
                         5 + kDistExtra[d]};
      }
      return t;
    }();
    return *t;
  }
  void symbol(int s) {
    const Code& c = tables().sym[s];
    put(c.bits, c.n);
  }
  void match(int len, int dist) {
    const Tables& t = tables();
    put(t.len[len].bits, t.len[len].n);
    put(t.dist[dist].bits, t.dist[dist].n);
  }

  std::string& out_;
  uint64_t acc_ = 0;
  int nbits_ = 0;
};

void be32(std::string& s, uint32_t v) {
  for (int i = 3; i >= 0; --i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void chunk(std::string& png, const char type[4], const std::string& data) {
  be32(png, static_cast<uint32_t>(data.size()));
  std::string body(type, 4);
  body += data;
  png += body;
  be32(png, crc32(reinterpret_cast<const uint8_t*>(body.data()), body.size()));
}

}  // namespace

std::string encode_preview_png(const cv::Mat& grid, const knit::PreviewStyle& style) {
  if (grid.empty() || grid.type() != CV_8UC1)
    throw std::invalid_argument("encode_preview_png: the grid must be a non-empty CV_8UC1 image");
  const knit::StitchTiles tiles = knit::stitch_tiles(style);
  const int w = tiles.tile[0].cols, h = tiles.tile[0].rows;
  const long long width = static_cast<long long>(grid.cols) * w, height = static_cast<long long>(grid.rows) * h;
  if (width > 0x7fffffff || height > 0x7fffffff) return {};

  // Palette: the tiles' colours; index rows of each tile.
  std::map<uint32_t, int> index;
  std::string palette;
  std::vector<uint8_t> tile_rows[2];
  for (int t = 0; t < 2; ++t) {
    tile_rows[t].resize(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const cv::Vec3b c = tiles.tile[t].at<cv::Vec3b>(y, x);
        const uint32_t key = (uint32_t{c[2]} << 16) | (uint32_t{c[1]} << 8) | c[0];
        auto it = index.find(key);
        if (it == index.end()) {
          if (index.size() == 256) return {};
          it = index.emplace(key, static_cast<int>(index.size())).first;
          palette.push_back(static_cast<char>(c[2]));  // PNG palettes are R, G, B
          palette.push_back(static_cast<char>(c[1]));
          palette.push_back(static_cast<char>(c[0]));
        }
        tile_rows[t][static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(it->second);
      }
  }

  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  be32(ihdr, static_cast<uint32_t>(width));
  be32(ihdr, static_cast<uint32_t>(height));
  ihdr += std::string("\x08\x03\x00\x00\x00", 5);  // 8-bit palette, deflate, no filter, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "PLTE", palette);

  // zlib stream: header (deflate, 32 KB window, fastest), one fixed-Huffman block, Adler-32.
  std::string z("\x78\x01", 2);
  Adler adler;
  {
    FixedDeflate deflate(z);
    const size_t line_bytes = static_cast<size_t>(width) + 1;
    std::vector<uint8_t> line(line_bytes);
    // Uncompressed position just past the last copy of each (tile, tile row), or 0 for none.
    std::vector<long long> last(static_cast<size_t>(2 * h), 0);
    long long pos = 0;  // uncompressed bytes so far
    for (int gy = 0; gy < grid.rows; ++gy) {
      const uint8_t* g = grid.ptr<uint8_t>(gy);
      for (int ty = 0; ty < h; ++ty, pos += static_cast<long long>(line_bytes)) {
        line[0] = 0;  // filter: none
        for (int x = 0; x < grid.cols; ++x)
          std::memcpy(&line[1 + static_cast<size_t>(x) * w], &tile_rows[g[x] != 0][static_cast<size_t>(ty) * w], w);
        adler.update(line.data(), line_bytes);
        deflate.literal(0);
        for (int x = 0; x < grid.cols;) {
          const int t = g[x] != 0;
          int end = x + 1;
          while (end < grid.cols && (g[end] != 0) == t) ++end;
          const long long at = pos + 1 + static_cast<long long>(x) * w;  // this run's first byte
          const uint8_t* bytes = &line[1 + static_cast<size_t>(x) * w];
          long long& prev = last[static_cast<size_t>(2 * ty + t)];
          // The first stitch: a copy of the last same tile row, when within the window.
          const long long d = prev > 0 ? at - (prev - w) : 0;
          if (d > 0 && d <= 32768 && w >= 3) {
            deflate.copy(static_cast<size_t>(w), static_cast<int>(d), bytes);
          } else {
            for (int i = 0; i < w; ++i) deflate.literal(bytes[i]);
          }
          // The rest of the run repeats the first stitch.
          const size_t rest = static_cast<size_t>(end - x - 1) * w;
          if (rest > 0) deflate.copy(rest, w, bytes + w);
          prev = pos + 1 + static_cast<long long>(end) * w;
          x = end;
        }
      }
    }
    deflate.finish();
  }
  be32(z, adler.value());
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

}  // namespace atelier

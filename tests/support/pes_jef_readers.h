// Readers of PES (with its PEC section) and JEF stitch files for the tests, written from the
// format descriptions (shared/protocols/embroidery-formats.md, the published PES/PEC and JEF
// layouts) by offsets and bit fields, not by calling the writers. They decode the records into
// the Rec/Ev of stitch_file_readers.h and collect every deviation from the format in `errors`
// rather than stopping, so a test can say what is wrong.
// PEC records are in 0.1 mm with +y DOWN; JEF's with +y up (like DST and EXP).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "tests/support/stitch_file_readers.h"

namespace atelier::embroidery::test {

struct Bytes {
  const std::string& s;
  std::vector<std::string>* errors;
  bool has(size_t at, size_t n) const { return at + n <= s.size(); }
  unsigned u8(size_t at) const {
    if (!has(at, 1)) {
      errors->push_back("read past the end at " + std::to_string(at));
      return 0;
    }
    return static_cast<std::uint8_t>(s[at]);
  }
  unsigned u16(size_t at) const { return u8(at) | u8(at + 1) << 8; }
  int s16(size_t at) const { return static_cast<std::int16_t>(u16(at)); }
  unsigned long u24(size_t at) const { return u16(at) | static_cast<unsigned long>(u8(at + 2)) << 16; }
  long s32(size_t at) const {
    return static_cast<std::int32_t>(u16(at) | static_cast<std::uint32_t>(u16(at + 2)) << 16);
  }
  float f32(size_t at) const {
    const std::uint32_t b = u16(at) | static_cast<std::uint32_t>(u16(at + 2)) << 16;
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  }
};

// ---- PES v1 + PEC ---------------------------------------------------------------------------
struct PesSegment {
  int flag = 0, color = 0;
  std::vector<std::pair<int, int>> points;
};

struct PesFile {
  std::string signature;
  size_t pec_offset = 0;
  int scale_to_fit = -1, hoop = -1, blocks = -1;
  float affine[6] = {};
  int block_width = 0, block_height = 0;
  std::vector<PesSegment> segments;
  std::vector<std::pair<int, int>> color_log;  // (segment, thread)
  // PEC
  std::string label;
  int thumb_stride = 0, thumb_height = 0;
  std::vector<int> threads;         // thread index per colour block
  size_t stitch_block = 0;          // offset of the stitch block
  unsigned long stitch_block_length = 0;
  int width = 0, height = 0;        // PEC's design size
  std::vector<Rec> records;         // +y down
  size_t end_code = 0;              // offset of FF
  std::vector<std::string> thumbs;  // 228 bytes each
  std::vector<std::string> errors;
};

inline PesFile read_pes(const std::string& bytes) {
  PesFile f;
  Bytes b{bytes, &f.errors};
  if (bytes.size() < 22) {
    f.errors.push_back("shorter than a PES header");
    return f;
  }
  f.signature = bytes.substr(0, 8);
  f.pec_offset = b.s32(8);
  f.scale_to_fit = static_cast<int>(b.u16(12));
  f.hoop = static_cast<int>(b.u16(14));
  f.blocks = static_cast<int>(b.u16(16));
  size_t at = 18;
  if (f.blocks > 0) {
    if (b.u16(at) != 0xFFFF || b.u16(at + 2) != 0) f.errors.push_back("no FFFF 0000 before CEmbOne");
    at += 4;
    if (b.u16(at) != 7 || bytes.compare(at + 2, 7, "CEmbOne") != 0) f.errors.push_back("no CEmbOne");
    at += 9;
    for (int i = 0; i < 8; ++i, at += 2)
      if (b.u16(at) != 0) f.errors.push_back("CEmbOne bounds not zero");
    for (int i = 0; i < 6; ++i, at += 4) f.affine[i] = b.f32(at);
    if (b.u16(at) != 1 || b.u16(at + 2) != 0 || b.u16(at + 4) != 0) f.errors.push_back("CEmbOne 1 0 0 missing");
    f.block_width = b.s16(at + 6);
    f.block_height = b.s16(at + 8);
    at += 10 + 8;
    const int sections = static_cast<int>(b.u16(at));
    at += 2;
    if (b.u16(at) != 0xFFFF || b.u16(at + 2) != 0) f.errors.push_back("no FFFF 0000 before CSewSeg");
    at += 4;
    if (b.u16(at) != 7 || bytes.compare(at + 2, 7, "CSewSeg") != 0) f.errors.push_back("no CSewSeg");
    at += 9;
    for (int s = 0; s < sections && b.has(at, 6); ++s) {
      if (s) {
        if (b.u16(at) != 0x8003) f.errors.push_back("no 8003 between segments");
        at += 2;
      }
      PesSegment seg;
      seg.flag = static_cast<int>(b.u16(at));
      seg.color = static_cast<int>(b.u16(at + 2));
      const unsigned n = b.u16(at + 4);
      at += 6;
      for (unsigned k = 0; k < n && b.has(at, 4); ++k, at += 4) seg.points.push_back({b.s16(at), b.s16(at + 2)});
      f.segments.push_back(seg);
    }
    const unsigned log = b.u16(at);
    at += 2;
    for (unsigned k = 0; k < log; ++k, at += 4) f.color_log.push_back({static_cast<int>(b.u16(at)), static_cast<int>(b.u16(at + 2))});
    if (b.u16(at) != 0 || b.u16(at + 2) != 0) f.errors.push_back("no 0000 0000 after the blocks");
    at += 4;
  } else {
    at += 4;
  }
  if (at != f.pec_offset) f.errors.push_back("the PES part ends at " + std::to_string(at) + ", not at the PEC offset");
  // PEC: "LA:", 16-character label, CR at +19; stride at +34, height at +35; count - 1 at +48.
  const size_t p = f.pec_offset;
  if (!b.has(p, 512 + 12)) {
    f.errors.push_back("no PEC section at the PEC offset");
    return f;
  }
  if (bytes.compare(p, 3, "LA:") != 0) f.errors.push_back("PEC does not start with LA:");
  f.label = bytes.substr(p + 3, 16);
  if (bytes[p + 19] != '\r') f.errors.push_back("label not ended by CR");
  if (b.u8(p + 32) != 0xFF || b.u8(p + 33) != 0x00) f.errors.push_back("no FF 00 after the label");
  f.thumb_stride = static_cast<int>(b.u8(p + 34));
  f.thumb_height = static_cast<int>(b.u8(p + 35));
  const int count = static_cast<int>(b.u8(p + 48)) + 1;
  for (int i = 0; i < count; ++i) f.threads.push_back(static_cast<int>(b.u8(p + 49 + i)));
  for (size_t i = p + 49 + count; i < p + 512; ++i)
    if (bytes[i] != ' ') {
      f.errors.push_back("PEC header padding is not spaces");
      break;
    }
  f.stitch_block = p + 512;
  const size_t sb = f.stitch_block;
  if (b.u16(sb) != 0) f.errors.push_back("stitch block does not start with 00 00");
  f.stitch_block_length = b.u24(sb + 2);
  if (b.u8(sb + 5) != 0x31 || b.u8(sb + 6) != 0xFF || b.u8(sb + 7) != 0xF0) f.errors.push_back("no 31 FF F0");
  f.width = static_cast<int>(b.u16(sb + 8));
  f.height = static_cast<int>(b.u16(sb + 10));
  size_t i = sb + 16;
  auto coord = [&](int& v, unsigned& flags) {
    const unsigned c = b.u8(i++);
    if (c & 0x80) {
      flags |= c & 0x70;
      const unsigned twelve = (c & 0x0F) << 8 | b.u8(i++);
      v = twelve >= 0x800 ? static_cast<int>(twelve) - 0x1000 : static_cast<int>(twelve);
      return true;
    }
    v = c >= 0x40 ? static_cast<int>(c) - 0x80 : static_cast<int>(c);
    return false;
  };
  while (true) {
    if (!b.has(i, 1)) {
      f.errors.push_back("no end code FF");
      return f;
    }
    const unsigned c = b.u8(i);
    if (c == 0xFF) {
      f.end_code = i++;
      f.records.push_back({Ev::end});
      break;
    }
    if (c == 0xFE) {
      if (b.u8(i + 1) != 0xB0) f.errors.push_back("FE not followed by B0");
      const unsigned n = b.u8(i + 2);
      if (n != 1 && n != 2) f.errors.push_back("colour change byte not 1 or 2");
      f.records.push_back({Ev::color});
      i += 3;
      continue;
    }
    int dx = 0, dy = 0;
    unsigned fx = 0, fy = 0;
    const bool lx = coord(dx, fx), ly = coord(dy, fy);
    if (fx != fy || ((fx & 0x30) && !(lx && ly))) f.errors.push_back("jump/trim flag on one axis only");
    if ((fx & 0x30) == 0x30 || (fx & 0x40)) f.errors.push_back("unknown flag combination");
    if (fx & 0x20) {
      f.records.push_back({Ev::trim});
      if (dx || dy) f.records.push_back({Ev::jump, dx, dy});
    } else if (fx & 0x10) {
      f.records.push_back({Ev::jump, dx, dy});
    } else {
      f.records.push_back({Ev::stitch, dx, dy});
    }
  }
  if (sb + f.stitch_block_length != i) f.errors.push_back("stitch block length does not end at the end code");
  const size_t thumb = static_cast<size_t>(f.thumb_stride) * static_cast<size_t>(f.thumb_height);
  for (size_t g = sb + f.stitch_block_length; thumb && g + thumb <= bytes.size(); g += thumb)
    f.thumbs.push_back(bytes.substr(g, thumb));
  if (thumb && (bytes.size() - (sb + f.stitch_block_length)) % thumb != 0)
    f.errors.push_back("the file does not end after whole thumbnails");
  return f;
}

// PEC's y is down; the round-trip checks (stitch_file_fixture.h) take DST's y up.
inline std::vector<Rec> y_up(std::vector<Rec> recs) {
  for (Rec& r : recs) r.dy = -r.dy;
  return recs;
}

// Whether pixel (x, y) of a PEC thumbnail is set: bit x % 8 of byte y * stride + x / 8.
inline bool thumb_bit(const std::string& t, int stride, int x, int y) {
  return (static_cast<std::uint8_t>(t[static_cast<size_t>(y * stride + x / 8)]) >> (x % 8)) & 1;
}

// ---- JEF ---------------------------------------------------------------------------------
struct JefFile {
  long stitch_offset = 0, flags = 0;
  std::string date;  // 14 characters
  long threads_count = 0, stitch_count = 0, hoop = -1;
  long extents[4] = {};    // left, top, right, bottom
  long edges[4][4] = {};   // 110x110, 50x50, 140x200, custom: left, top, right, bottom
  std::vector<long> threads, thread_types;
  std::vector<Rec> records;  // +y up; trims folded (three zero jumps)
  long body_words = 0;       // body bytes / 2
  std::vector<std::string> errors;
};

inline JefFile read_jef(const std::string& bytes) {
  JefFile f;
  Bytes b{bytes, &f.errors};
  if (bytes.size() < 0x74) {
    f.errors.push_back("shorter than a JEF header");
    return f;
  }
  f.stitch_offset = b.s32(0);
  f.flags = b.s32(4);
  f.date = bytes.substr(8, 14);
  if (b.u8(22) != 0 || b.u8(23) != 0) f.errors.push_back("date not followed by 00 00");
  f.threads_count = b.s32(24);
  f.stitch_count = b.s32(28);
  f.hoop = b.s32(32);
  for (int k = 0; k < 4; ++k) f.extents[k] = b.s32(36 + 4 * k);
  for (int h = 0; h < 4; ++h)
    for (int k = 0; k < 4; ++k) f.edges[h][k] = b.s32(52 + 16 * h + 4 * k);
  for (long k = 0; k < f.threads_count && k < 1000; ++k) f.threads.push_back(b.s32(0x74 + 4 * k));
  for (long k = 0; k < f.threads_count && k < 1000; ++k)
    f.thread_types.push_back(b.s32(0x74 + 4 * f.threads_count + 4 * k));
  if (f.stitch_offset != 0x74 + 8 * f.threads_count) f.errors.push_back("stitch offset is not 0x74 + 8 x threads");
  std::vector<Rec> raw;
  size_t i = static_cast<size_t>(f.stitch_offset);
  bool ended = false;
  auto s8 = [&](size_t k) { return static_cast<int>(static_cast<signed char>(b.u8(k))); };
  while (b.has(i, 2)) {
    if (b.u8(i) != 0x80) {
      raw.push_back({Ev::stitch, s8(i), s8(i + 1)});
      i += 2;
      continue;
    }
    const unsigned c = b.u8(i + 1);
    if (c == 0x10) {
      raw.push_back({Ev::end});
      i += 2;
      ended = true;
      break;
    }
    if (!b.has(i, 4)) {
      f.errors.push_back("truncated control record");
      break;
    }
    if (c == 0x01) {
      raw.push_back({Ev::color});
      if (b.u8(i + 2) || b.u8(i + 3)) f.errors.push_back("colour change with a move");
    } else if (c == 0x02) {
      raw.push_back({Ev::jump, s8(i + 2), s8(i + 3)});
    } else {
      f.errors.push_back("unknown control 80 " + std::to_string(c));
    }
    i += 4;
  }
  if (!ended) f.errors.push_back("no end code 80 10");
  if (i != bytes.size()) f.errors.push_back("bytes after the end code");
  f.body_words = static_cast<long>((i - static_cast<size_t>(f.stitch_offset)) / 2);
  for (size_t k = 0; k < raw.size(); ++k) {
    auto zero_jump = [&](size_t n) { return n < raw.size() && raw[n].type == Ev::jump && !raw[n].dx && !raw[n].dy; };
    if (zero_jump(k) && zero_jump(k + 1) && zero_jump(k + 2)) {
      f.records.push_back({Ev::trim});
      k += 2;
    } else {
      f.records.push_back(raw[k]);
    }
  }
  return f;
}

}  // namespace atelier::embroidery::test

// Readers of DST and EXP stitch files for the tests, written from the formats file
// (shared/protocols/embroidery-formats.md) independently of the writers in convert/embroidery.
// They decode records (file units: 0.1 mm, +y up) and collect every deviation from the format in
// `errors` rather than stopping, so a test can say what is wrong.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace atelier::embroidery::test {

enum class Ev { stitch, jump, trim, color, end };

// One body record in file units (0.1 mm, +y up).
struct Rec {
  Ev type;
  int dx = 0, dy = 0;
};

// ---- DST reader -------------------------------------------------------------------------
// The bit table exactly as the formats file lists it, bits 7..0 of bytes 0 and 1 and bits
// 5..2 of byte 2.
const char* const kDstBits[3][8] = {
    {"y+1", "y-1", "y+9", "y-9", "x-9", "x+9", "x-1", "x+1"},
    {"y+3", "y-3", "y+27", "y-27", "x-27", "x+27", "x-3", "x+3"},
    {"J", "C", "y+81", "y-81", "x-81", "x+81", "1", "1"},
};

struct DstFile {
  std::map<std::string, std::string> header;  // "ST" -> "    123"
  std::string header_tail;                    // bytes after the last CR-ended field
  std::vector<Rec> records;
  std::vector<std::string> errors;
};

inline DstFile read_dst(const std::string& bytes) {
  DstFile f;
  if (bytes.size() < 512) {
    f.errors.push_back("shorter than a header");
    return f;
  }
  size_t i = 0;
  while (i < 512 && bytes[i] != '\x1A') {
    const size_t cr = bytes.find('\r', i);
    if (cr == std::string::npos || cr >= 512) break;
    const std::string fieldtext = bytes.substr(i, cr - i);
    f.header[fieldtext.substr(0, 2)] = fieldtext.substr(3);
    if (fieldtext.size() < 3 || fieldtext[2] != ':') f.errors.push_back("bad field " + fieldtext);
    i = cr + 1;
  }
  f.header_tail = bytes.substr(i, 512 - i);
  if ((bytes.size() - 512) % 3 != 0) f.errors.push_back("body is not whole records");
  for (size_t r = 512; r + 3 <= bytes.size(); r += 3) {
    const std::uint8_t b[3] = {static_cast<std::uint8_t>(bytes[r]),
                               static_cast<std::uint8_t>(bytes[r + 1]),
                               static_cast<std::uint8_t>(bytes[r + 2])};
    if ((b[2] & 0x03) != 0x03) f.errors.push_back("bits 1,0 of byte 2 not set");
    Rec rec{Ev::stitch};
    if (b[2] == 0xF3 && b[0] == 0 && b[1] == 0) {
      rec.type = Ev::end;
    } else if ((b[2] & 0xC0) == 0xC0) {
      rec.type = Ev::color;
    } else if (b[2] & 0x80) {
      rec.type = Ev::jump;
    } else if (b[2] & 0x40) {
      f.errors.push_back("colour bit without jump bit");
    }
    if (rec.type != Ev::end) {
      for (int byte = 0; byte < 3; ++byte) {
        for (int bit = 7; bit >= 0; --bit) {
          if (!(b[byte] & (1u << bit))) continue;
          const std::string name = kDstBits[byte][7 - bit];
          if (name[0] != 'x' && name[0] != 'y') continue;
          const int v = std::stoi(name.substr(2)) * (name[1] == '+' ? 1 : -1);
          (name[0] == 'x' ? rec.dx : rec.dy) += v;
        }
      }
      // A digit with both its + and - bit set is not balanced ternary.
      for (int byte = 0; byte < 3; ++byte)
        for (int bit = 7; bit >= 1; --bit) {
          const std::string a = kDstBits[byte][7 - bit], c = kDstBits[byte][7 - bit + 1];
          if ((b[byte] & (1u << bit)) && (b[byte] & (1u << (bit - 1))) && a.size() > 1 &&
              c.size() > 1 && a[0] == c[0] && a.substr(2) == c.substr(2))
            f.errors.push_back("digit with both signs");
        }
    }
    f.records.push_back(rec);
  }
  return f;
}

// A header number: sign and digits, padded with spaces ("-  215").
inline long num(const std::string& field) {
  std::string t;
  for (char c : field)
    if (c != ' ') t += c;
  size_t used = 0;
  const long v = std::stol(t, &used);
  EXPECT_EQ(used, t.size()) << "not a number: '" << field << "'";
  return v;
}

// DST carries a trim as jumps (+2,+2), (-4,-4), (+2,+2): fold them back into one trim.
inline std::vector<Rec> fold_dst_trims(const std::vector<Rec>& recs) {
  std::vector<Rec> out;
  for (size_t i = 0; i < recs.size(); ++i) {
    auto is = [&](size_t k, int dx, int dy) {
      return k < recs.size() && recs[k].type == Ev::jump && recs[k].dx == dx && recs[k].dy == dy;
    };
    if (is(i, 2, 2) && is(i + 1, -4, -4) && is(i + 2, 2, 2)) {
      out.push_back({Ev::trim});
      i += 2;
    } else {
      out.push_back(recs[i]);
    }
  }
  return out;
}

// ---- EXP reader -------------------------------------------------------------------------
struct ExpFile {
  std::vector<Rec> records;
  std::vector<std::string> errors;
};

inline ExpFile read_exp(const std::string& bytes) {
  ExpFile f;
  auto s8 = [&](size_t k) { return static_cast<int>(static_cast<signed char>(bytes[k])); };
  size_t i = 0;
  while (i < bytes.size()) {
    const auto b0 = static_cast<std::uint8_t>(bytes[i]);
    if (b0 == 0x80) {
      if (i + 4 > bytes.size()) {
        f.errors.push_back("truncated control record");
        break;
      }
      const auto c = static_cast<std::uint8_t>(bytes[i + 1]);
      if (c == 0x04) {
        f.records.push_back({Ev::jump, s8(i + 2), s8(i + 3)});
      } else if (c == 0x80 && bytes[i + 2] == 0x07 && bytes[i + 3] == 0x00) {
        f.records.push_back({Ev::trim});
      } else if (c == 0x01 && bytes[i + 2] == 0 && bytes[i + 3] == 0) {
        f.records.push_back({Ev::color});
      } else {
        f.errors.push_back("unknown control record");
      }
      i += 4;
    } else {
      if (i + 2 > bytes.size()) {
        f.errors.push_back("truncated stitch");
        break;
      }
      f.records.push_back({Ev::stitch, s8(i), s8(i + 1)});
      i += 2;
    }
  }
  return f;
}

}  // namespace atelier::embroidery::test

#include "convert/embroidery/thread_palettes.h"

#include <array>
#include <cmath>
#include <limits>

namespace atelier::embroidery {
namespace {

std::array<double, 3> to_lab(std::uint32_t rgb) {
  auto linear = [](int c8) {
    const double c = c8 / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  const double r = linear((rgb >> 16) & 0xff), g = linear((rgb >> 8) & 0xff), b = linear(rgb & 0xff);
  // sRGB -> XYZ, relative to the D65 white.
  const double x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
  const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
  const double z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883;
  auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  return {116.0 * f(y) - 16.0, 500.0 * (f(x) - f(y)), 200.0 * (f(y) - f(z))};
}

int nearest_free(const std::vector<Thread>& table, std::uint32_t rgb, const std::vector<bool>& taken) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < table.size(); ++i) {
    if (taken[i]) continue;
    const double d = color_difference(rgb, table[i].rgb);
    if (d < best_d) best_d = d, best = static_cast<int>(i);
  }
  return best;
}

}  // namespace

const std::vector<Thread>& pec_threads() {
  static const std::vector<Thread> t{
    {0x0E1F7C, "Prussian Blue", "1"},  // 1
    {0x0A55A3, "Blue", "2"},  // 2
    {0x008777, "Teal Green", "3"},  // 3
    {0x4B6BAF, "Cornflower Blue", "4"},  // 4
    {0xED171F, "Red", "5"},  // 5
    {0xD15C00, "Reddish Brown", "6"},  // 6
    {0x913697, "Magenta", "7"},  // 7
    {0xE49ACB, "Light Lilac", "8"},  // 8
    {0x915FAC, "Lilac", "9"},  // 9
    {0x9ED67D, "Mint Green", "10"},  // 10
    {0xE8A900, "Deep Gold", "11"},  // 11
    {0xFEBA35, "Orange", "12"},  // 12
    {0xFFFF00, "Yellow", "13"},  // 13
    {0x70BC1F, "Lime Green", "14"},  // 14
    {0xBA9800, "Brass", "15"},  // 15
    {0xA8A8A8, "Silver", "16"},  // 16
    {0x7D6F00, "Russet Brown", "17"},  // 17
    {0xFFFFB3, "Cream Brown", "18"},  // 18
    {0x4F5556, "Pewter", "19"},  // 19
    {0x000000, "Black", "20"},  // 20
    {0x0B3D91, "Ultramarine", "21"},  // 21
    {0x770176, "Royal Purple", "22"},  // 22
    {0x293133, "Dark Gray", "23"},  // 23
    {0x2A1301, "Dark Brown", "24"},  // 24
    {0xF64A8A, "Deep Rose", "25"},  // 25
    {0xB27624, "Light Brown", "26"},  // 26
    {0xFCBBC5, "Salmon Pink", "27"},  // 27
    {0xFE370F, "Vermilion", "28"},  // 28
    {0xF0F0F0, "White", "29"},  // 29
    {0x6A1C8A, "Violet", "30"},  // 30
    {0xA8DDC4, "Seacrest", "31"},  // 31
    {0x2584BB, "Sky Blue", "32"},  // 32
    {0xFEB343, "Pumpkin", "33"},  // 33
    {0xFFF36B, "Cream Yellow", "34"},  // 34
    {0xD0A660, "Khaki", "35"},  // 35
    {0xD15400, "Clay Brown", "36"},  // 36
    {0x66BA49, "Leaf Green", "37"},  // 37
    {0x134A46, "Peacock Blue", "38"},  // 38
    {0x878787, "Gray", "39"},  // 39
    {0xD8CCC6, "Warm Gray", "40"},  // 40
    {0x435607, "Dark Olive", "41"},  // 41
    {0xFDD9DE, "Flesh Pink", "42"},  // 42
    {0xF993BC, "Pink", "43"},  // 43
    {0x003822, "Deep Green", "44"},  // 44
    {0xB2AFD4, "Lavender", "45"},  // 45
    {0x686AB0, "Wisteria Violet", "46"},  // 46
    {0xEFE3B9, "Beige", "47"},  // 47
    {0xF73866, "Carmine", "48"},  // 48
    {0xB54B64, "Amber Red", "49"},  // 49
    {0x132B1A, "Olive Green", "50"},  // 50
    {0xC70156, "Dark Fuchsia", "51"},  // 51
    {0xFE9E32, "Tangerine", "52"},  // 52
    {0xA8DEEB, "Light Blue", "53"},  // 53
    {0x00673E, "Emerald Green", "54"},  // 54
    {0x4E2990, "Purple", "55"},  // 55
    {0x2F7E20, "Moss Green", "56"},  // 56
    {0xFFCCCC, "Flesh Pink", "57"},  // 57
    {0xFFD911, "Harvest Gold", "58"},  // 58
    {0x095BA6, "Electric Blue", "59"},  // 59
    {0xF0F970, "Lemon Yellow", "60"},  // 60
    {0xE3F35B, "Fresh Green", "61"},  // 61
    {0xFF9900, "Orange", "62"},  // 62
    {0xFFF08D, "Cream Yellow", "63"},  // 63
    {0xFFC8C8, "Applique", "64"},  // 64
  };
  return t;
}

const std::vector<Thread>& jef_threads() {
  static const std::vector<Thread> t{
    {0x000000, "Black", "002"},  // 1
    {0xFFFFFF, "White", "001"},  // 2
    {0xFFFF17, "Yellow", "204"},  // 3
    {0xFF6600, "Orange", "203"},  // 4
    {0x2F5933, "Olive Green", "219"},  // 5
    {0x237336, "Green", "226"},  // 6
    {0x65C2C8, "Sky", "217"},  // 7
    {0xAB5A96, "Purple", "208"},  // 8
    {0xF669A0, "Pink", "201"},  // 9
    {0xFF0000, "Red", "225"},  // 10
    {0xB1704E, "Brown", "214"},  // 11
    {0x0B2F84, "Blue", "207"},  // 12
    {0xE4C35D, "Gold", "003"},  // 13
    {0x481A05, "Dark Brown", "205"},  // 14
    {0xAC9CC7, "Pale Violet", "209"},  // 15
    {0xFCF294, "Pale Yellow", "210"},  // 16
    {0xF999B7, "Pale Pink", "211"},  // 17
    {0xFAB381, "Peach", "212"},  // 18
    {0xC9A480, "Beige", "213"},  // 19
    {0x970533, "Wine Red", "215"},  // 20
    {0xA0B8CC, "Pale Sky", "216"},  // 21
    {0x7FC21C, "Yellow Green", "218"},  // 22
    {0xE5E5E5, "Silver Gray", "220"},  // 23
    {0x889B9B, "Gray", "221"},  // 24
    {0x98D6BD, "Pale Aqua", "227"},  // 25
    {0xB2E1E3, "Baby Blue", "228"},  // 26
    {0x368BA0, "Powder Blue", "229"},  // 27
    {0x4F83AB, "Bright Blue", "230"},  // 28
    {0x386A91, "Slate Blue", "231"},  // 29
    {0x071650, "Navy Blue", "232"},  // 30
    {0xF999A2, "Salmon Pink", "233"},  // 31
    {0xF9676B, "Coral", "234"},  // 32
    {0xE3311F, "Burnt Orange", "235"},  // 33
    {0xE2A188, "Cinnamon", "236"},  // 34
    {0xB59474, "Umber", "237"},  // 35
    {0xE4CF99, "Blond", "238"},  // 36
    {0xFFCB00, "Sunflower", "239"},  // 37
    {0xE1ADD4, "Orchid Pink", "240"},  // 38
    {0xC3007E, "Peony Purple", "241"},  // 39
    {0x80004B, "Burgundy", "242"},  // 40
    {0x540571, "Royal Purple", "243"},  // 41
    {0xB10525, "Cardinal Red", "244"},  // 42
    {0xCAE0C0, "Opal Green", "245"},  // 43
    {0x899856, "Moss Green", "246"},  // 44
    {0x5C941A, "Meadow Green", "247"},  // 45
    {0x003114, "Dark Green", "248"},  // 46
    {0x5DAE94, "Aquamarine", "249"},  // 47
    {0x4CBF8F, "Emerald Green", "250"},  // 48
    {0x007772, "Peacock Green", "251"},  // 49
    {0x595B61, "Dark Gray", "252"},  // 50
    {0xFFFFF2, "Ivory White", "253"},  // 51
    {0xB15818, "Hazel", "254"},  // 52
    {0xCB8A07, "Toast", "255"},  // 53
    {0x986C80, "Salmon", "256"},  // 54
    {0x98692D, "Cocoa Brown", "257"},  // 55
    {0x4D3419, "Sienna", "258"},  // 56
    {0x4C330B, "Sepia", "259"},  // 57
    {0x33200A, "Dark Sepia", "260"},  // 58
    {0x523A97, "Violet Blue", "261"},  // 59
    {0x0D217E, "Blue Ink", "262"},  // 60
    {0x1E77AC, "Sola Blue", "263"},  // 61
    {0xB2DD53, "Green Dust", "264"},  // 62
    {0xF33689, "Crimson", "265"},  // 63
    {0xDE649E, "Floral Pink", "266"},  // 64
    {0x984161, "Wine", "267"},  // 65
    {0x4C5612, "Olive Drab", "268"},  // 66
    {0x4C881F, "Meadow", "269"},  // 67
    {0xE4DE79, "Mustard", "270"},  // 68
    {0xCB8A1A, "Yellow Ocher", "271"},  // 69
    {0xCBA21C, "Old Gold", "272"},  // 70
    {0xFF9805, "Honey Dew", "273"},  // 71
    {0xFCB257, "Tangerine", "274"},  // 72
    {0xFFE505, "Canary Yellow", "275"},  // 73
    {0xF0331F, "Vermilion", "202"},  // 74
    {0x1A842D, "Bright Green", "206"},  // 75
    {0x386CAE, "Ocean Blue", "222"},  // 76
    {0xE3C4B4, "Beige Gray", "223"},  // 77
    {0xE3AC81, "Bamboo", "224"},  // 78
  };
  return t;
}

double color_difference(std::uint32_t rgb_a, std::uint32_t rgb_b) {
  const auto a = to_lab(rgb_a), b = to_lab(rgb_b);
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

int nearest_thread(const std::vector<Thread>& table, std::uint32_t rgb) {
  return nearest_free(table, rgb, std::vector<bool>(table.size(), false)) + 1;
}

std::vector<int> assign_threads(const std::vector<Thread>& table, const std::vector<std::uint32_t>& colors) {
  std::vector<bool> taken(table.size(), false);
  std::vector<std::uint32_t> seen;  // distinct colours so far, with their index below
  std::vector<int> seen_index, out;
  out.reserve(colors.size());
  for (std::uint32_t c : colors) {
    int index = -1;
    for (size_t k = 0; k < seen.size(); ++k)
      if (seen[k] == c) index = seen_index[k];
    if (index < 0) {
      index = nearest_thread(table, c);
      if (taken[static_cast<size_t>(index - 1)]) {
        const int free = nearest_free(table, c, taken);
        if (free >= 0) index = free + 1;  // else the table is used up: share the nearest
      }
      taken[static_cast<size_t>(index - 1)] = true;
      seen.push_back(c);
      seen_index.push_back(index);
    }
    out.push_back(index);
  }
  return out;
}

std::vector<std::uint32_t> block_colors(const StitchPlan& plan) {
  const size_t blocks = static_cast<size_t>(stitch_stats(plan).color_changes) + 1;
  std::vector<std::uint32_t> out;
  out.reserve(blocks);
  for (size_t i = 0; i < blocks; ++i)
    out.push_back(i < plan.colors_rgb.size() ? plan.colors_rgb[i]
                                             : plan.colors_rgb.empty() ? 0x000000 : plan.colors_rgb.back());
  return out;
}

}  // namespace atelier::embroidery

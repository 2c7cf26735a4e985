#include "tools/laser_emu/settings.h"

#include <cmath>
#include <cstdio>

namespace atelier::laser_emu {
namespace {

enum class Fmt { integer, decimal3, rpm };

// GRBL's report order (report_grbl_settings) and print format per setting.
struct Entry {
  int id;
  Fmt fmt;
};
constexpr Entry kEntries[] = {
    {0, Fmt::integer},    {1, Fmt::integer},    {2, Fmt::integer},    {3, Fmt::integer},
    {4, Fmt::integer},    {5, Fmt::integer},    {6, Fmt::integer},    {10, Fmt::integer},
    {11, Fmt::decimal3},  {12, Fmt::decimal3},  {13, Fmt::integer},   {20, Fmt::integer},
    {21, Fmt::integer},   {22, Fmt::integer},   {23, Fmt::integer},   {24, Fmt::decimal3},
    {25, Fmt::decimal3},  {26, Fmt::integer},   {27, Fmt::decimal3},  {30, Fmt::rpm},
    {31, Fmt::rpm},       {32, Fmt::integer},   {100, Fmt::decimal3}, {101, Fmt::decimal3},
    {102, Fmt::decimal3}, {110, Fmt::decimal3}, {111, Fmt::decimal3}, {112, Fmt::decimal3},
    {120, Fmt::decimal3}, {121, Fmt::decimal3}, {122, Fmt::decimal3}, {130, Fmt::decimal3},
    {131, Fmt::decimal3}, {132, Fmt::decimal3},
};

constexpr int kStatusOk = 0, kInvalidStatement = 3, kNegativeValue = 4, kStepPulseMin = 6,
              kSoftLimitError = 10;

}  // namespace

Settings::Settings(double work_w_mm, double work_h_mm) {
  restore_defaults();
  // What the owner of a diode laser stores over the compiled defaults.
  values_[32] = 1;
  values_[130] = work_w_mm;
  values_[131] = work_h_mm;
  values_[100] = values_[101] = 80;
  values_[110] = values_[111] = 6000;
  values_[120] = values_[121] = 500;
}

void Settings::restore_defaults() {
  // defaults.h, DEFAULTS_GENERIC (accelerations in mm/s^2 as "$$" shows them).
  values_ = {
      {0, 10},     {1, 25},     {2, 0},      {3, 0},      {4, 0},      {5, 0},      {6, 0},
      {10, 1},     {11, 0.010}, {12, 0.002}, {13, 0},     {20, 0},     {21, 0},     {22, 0},
      {23, 0},     {24, 25},    {25, 500},   {26, 250},   {27, 1},     {30, 1000},  {31, 0},
      {32, 0},     {100, 250},  {101, 250},  {102, 250},  {110, 500},  {111, 500},  {112, 500},
      {120, 10},   {121, 10},   {122, 10},   {130, 200},  {131, 200},  {132, 200},
  };
}

double Settings::get(int id) const {
  const auto it = values_.find(id);
  return it == values_.end() ? 0.0 : it->second;
}

std::string Settings::listing() const {
  std::string out;
  char buf[64];
  for (const auto& e : kEntries) {
    const double v = get(e.id);
    switch (e.fmt) {
      case Fmt::integer: std::snprintf(buf, sizeof buf, "$%d=%d\r\n", e.id, static_cast<int>(v)); break;
      case Fmt::decimal3: std::snprintf(buf, sizeof buf, "$%d=%.3f\r\n", e.id, v); break;
      case Fmt::rpm: std::snprintf(buf, sizeof buf, "$%d=%.0f\r\n", e.id, v); break;
    }
    out += buf;
  }
  return out;
}

int Settings::store(double param, double value) {
  if (value < 0.0) return kNegativeValue;
  if (param != std::trunc(param) || param < 0 || param > 255) return kInvalidStatement;
  const int id = static_cast<int>(param);
  bool known = false;
  Fmt fmt = Fmt::decimal3;
  for (const auto& e : kEntries)
    if (e.id == id) known = true, fmt = e.fmt;
  if (!known) return kInvalidStatement;
  // Integer settings keep the truncated value in a uint8, as GRBL does (300 is stored as 44):
  // never a value an int cast of it could overflow on.
  const double v = fmt == Fmt::integer ? std::fmod(std::trunc(value), 256.0) : value;
  switch (id) {
    case 0:
      if (v < 3) return kStepPulseMin;
      break;
    case 20:
      if (v != 0 && !homing()) return kSoftLimitError;
      values_[20] = v != 0;
      return kStatusOk;
    case 22:
      if (v == 0) values_[20] = 0;  // GRBL forces soft limits off with homing
      values_[22] = v != 0;
      return kStatusOk;
    case 4: case 5: case 6: case 13: case 21: case 32:
      values_[id] = v != 0;  // boolean flags
      return kStatusOk;
    default: break;
  }
  values_[id] = v;
  return kStatusOk;
}

}  // namespace atelier::laser_emu

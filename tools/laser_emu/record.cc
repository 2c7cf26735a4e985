#include "tools/laser_emu/record.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace atelier::laser_emu {

void Record::add_event(double t, std::string name, std::optional<int> code, std::optional<long> line) {
  events.push_back(Event{t, std::move(name), code, line});
  ++version;
}

void Record::add_segment(const Segment& s) {
  segments.push_back(s);
  ++version;
}

nlohmann::json to_json(const Record& r) {
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : r.segments)
    segs.push_back({{"t0", s.t0}, {"t1", s.t1}, {"x0", s.x0}, {"y0", s.y0}, {"x1", s.x1}, {"y1", s.y1},
                    {"s", s.s}, {"power", s.power}, {"mode", s.mode}, {"feed", s.feed}});
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : r.events) {
    nlohmann::json j = {{"t", e.t}, {"event", e.event}};
    if (e.code) j["code"] = *e.code;
    if (e.line) j["line"] = *e.line;
    events.push_back(std::move(j));
  }
  return {{"segments", std::move(segs)},
          {"events", std::move(events)},
          {"rx_overflows", r.rx_overflows},
          {"max_rx_bytes", r.max_rx_bytes},
          {"lines_received", r.lines_received},
          {"errors", r.errors},
          {"work_area_mm", {r.work_w_mm, r.work_h_mm}}};
}

cv::Mat render_burn(const Record& r, double ppm) {
  const int w = std::max(1, static_cast<int>(std::lround(r.work_w_mm * ppm)));
  const int h = std::max(1, static_cast<int>(std::lround(r.work_h_mm * ppm)));
  cv::Mat img(h, w, CV_8UC1, cv::Scalar(255));
  const int thickness = std::max(1, static_cast<int>(std::lround(0.2 * ppm)));
  // Weakest first, so where burns overlap the strongest shows.
  std::vector<const Segment*> burned;
  for (const auto& s : r.segments)
    if (s.power > 0) burned.push_back(&s);
  std::stable_sort(burned.begin(), burned.end(), [](auto* a, auto* b) { return a->power < b->power; });
  constexpr int kShift = 4;  // sub-pixel endpoints
  constexpr double kScale = 1 << kShift;
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * ppm * kScale)),
                     static_cast<int>(std::lround((r.work_h_mm - y) * ppm * kScale)));
  };
  for (const Segment* s : burned) {
    // Full power is black; the faintest burn is still clearly darker than the white stock.
    const double grey = 200.0 * (1.0 - std::min(1.0, s->power));
    cv::line(img, px(s->x0, s->y0), px(s->x1, s->y1), cv::Scalar(grey), thickness, cv::LINE_8, kShift);
  }
  return img;
}

}  // namespace atelier::laser_emu

#include "wire/actor_convert.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "wire/sample.h"

namespace studio::wire {

Expected<hull::SegmentSet> to_core(const studio_SegmentSet& s) {
  const std::string who = "segments " + std::string(str(s.actor_id));
  if (s.axis > 2) return fail(who + ": axis " + std::to_string(s.axis) + " is not 0, 1 or 2");
  hull::GridSpec grid;
  grid.axis = hull::Axis(s.axis);
  for (int k = 0; k < 3; ++k) {
    grid.box_min[k] = s.box_min[k];
    grid.box_max[k] = s.box_max[k];
  }
  if (s.nu > 8192 || s.nv > 8192) return fail(who + ": grid larger than 8192 columns a side");
  grid.cells_u = int(s.nu);
  grid.cells_v = int(s.nv);
  if (auto ok = grid.validate(); !ok) return fail(who + ": " + ok.error().message);

  const auto start = view(s.interval_start);
  const auto iv = view(s.intervals);
  const std::size_t columns = grid.columns();
  if (start.size() != columns + 1 || start.front() != 0 ||
      iv.size() != std::size_t(start.back()) * 2)
    return fail(who + ": interval table inconsistent with its " + std::to_string(s.nu) + "x" +
                std::to_string(s.nv) + " grid");
  const float t_lo = s.box_min[s.axis], t_hi = s.box_max[s.axis];
  std::vector<hull::Interval> out;
  std::vector<uint32_t> out_start(columns + 1, 0);
  out.reserve(start.back());
  for (std::size_t c = 0; c < columns; ++c) {
    if (start[c + 1] < start[c]) return fail(who + ": interval offsets decrease");
    const std::size_t column_begin = out.size();
    for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
      const float b = iv[2 * std::size_t(k)], e = iv[2 * std::size_t(k) + 1];
      if (!std::isfinite(b) || !std::isfinite(e) || b > e || b < t_lo || e > t_hi)
        return fail(who + ": interval outside its column or reversed");
      if (out.size() > column_begin && b < out.back().hi)
        return fail(who + ": intervals of a column unsorted or overlapping");
      if (b == e) continue;  // zero length: nothing occupied
      if (out.size() > column_begin && b == out.back().hi)
        out.back().hi = e;  // touching: one interval
      else
        out.push_back({b, e});
    }
    out_start[c + 1] = uint32_t(out.size());
  }
  hull::SegmentSet set = hull::SegmentSet::empty(grid);
  set.assign(std::move(out), std::move(out_start));
  return set;
}

void from_core(const hull::SegmentSet& set, studio_SegmentSet& s) {
  if (!set.valid()) throw std::invalid_argument("wire::from_core: invalid hull::SegmentSet");
  const hull::GridSpec& g = set.grid();
  s.nu = uint32_t(g.cells_u);
  s.nv = uint32_t(g.cells_v);
  for (int k = 0; k < 3; ++k) {
    s.box_min[k] = float(g.box_min[k]);
    s.box_max[k] = float(g.box_max[k]);
  }
  s.axis = uint8_t(g.a());
  assign(s.interval_start, set.start());
  resize(s.intervals, uint32_t(set.interval_count() * 2));
  auto iv = view(s.intervals);
  const float t_lo = s.box_min[s.axis], t_hi = s.box_max[s.axis];
  for (std::size_t k = 0; k < set.interval_count(); ++k) {
    // Clamp to the float box so the receiver's range check holds after the double → float cast.
    iv[2 * k] = std::clamp(set.intervals()[k].lo, t_lo, t_hi);
    iv[2 * k + 1] = std::clamp(set.intervals()[k].hi, t_lo, t_hi);
  }
}

Expected<tracker::HeadPose> to_core(const studio_HeadPose& s) {
  tracker::HeadPose p;
  p.position = {s.position[0], s.position[1], s.position[2]};
  p.velocity = {s.velocity[0], s.velocity[1], s.velocity[2]};
  p.confidence = s.confidence;
  p.capture_ns = s.capture_ns;
  if (!p.position.allFinite() || !p.velocity.allFinite() || !std::isfinite(p.confidence))
    return fail("head " + std::string(str(s.actor_id)) + ": position or velocity not finite");
  if (p.confidence < 0 || p.confidence > 1)
    return fail("head " + std::string(str(s.actor_id)) + ": confidence outside [0, 1]");
  return p;
}

void from_core(const tracker::HeadPose& p, studio_HeadPose& s) {
  for (int k = 0; k < 3; ++k) {
    s.position[k] = p.position[k];
    s.velocity[k] = p.velocity[k];
  }
  s.confidence = std::clamp(p.confidence, 0.0, 1.0);
  s.capture_ns = p.capture_ns;
}

}  // namespace studio::wire

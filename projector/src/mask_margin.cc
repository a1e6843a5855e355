#include "projector/mask_margin.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace studio::projector {

Expected<void> MarginOptions::validate() const {
  if (!(floor_m >= 0) || !std::isfinite(floor_m)) return fail("margin: floor_m must be >= 0");
  if (!(cap_m >= floor_m) || !std::isfinite(cap_m)) return fail("margin: cap_m must be >= floor_m");
  if (!(velocity_uncertainty_mps >= 0) || !std::isfinite(velocity_uncertainty_mps))
    return fail("margin: velocity_uncertainty_mps must be >= 0");
  if (!(head_disagreement_mps >= 0) || !std::isfinite(head_disagreement_mps))
    return fail("margin: head_disagreement_mps must be >= 0");
  if (!(max_acceleration_mps2 > 0) || !std::isfinite(max_acceleration_mps2))
    return fail("margin: max_acceleration_mps2 must be > 0");
  return {};
}

Expected<Margin> security_margin(const MarginOptions& options, double latency_s,
                                 double head_speed_mps, const MeshMotion* motion,
                                 double velocity_age_s) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  if (!(latency_s >= 0) || !std::isfinite(latency_s)) return fail("margin: latency must be >= 0");
  if (!(head_speed_mps >= 0) || !std::isfinite(head_speed_mps))
    return fail("margin: head speed must be >= 0");
  if (!std::isfinite(velocity_age_s)) return fail("margin: velocity age must be finite");
  Margin m;
  m.floor_m = options.floor_m;
  m.latency_s = latency_s;
  m.speed_mps = std::max(head_speed_mps, motion != nullptr ? motion->max_speed_mps : 0.0);
  const bool can_predict = options.prediction && motion != nullptr &&
                           motion->max_acceleration_mps2 &&
                           head_speed_mps <= motion->max_speed_mps + options.head_disagreement_mps;
  if (can_predict) {
    m.predicted = true;
    const double a =
        options.worst_case_acceleration
            ? options.max_acceleration_mps2
            : motion->robust_acceleration_mps2.value_or(*motion->max_acceleration_mps2);
    m.acceleration_bounded = a > options.max_acceleration_mps2;
    m.acceleration_mps2 = std::min(a, options.max_acceleration_mps2);
    m.velocity_age_s = velocity_age_s >= 0 ? velocity_age_s : 0.5 * motion->dt_s;
    m.motion_m = 0.5 * m.acceleration_mps2 * latency_s * (latency_s + 2 * m.velocity_age_s) +
                 options.velocity_uncertainty_mps * latency_s;
  } else {
    // The mask stays where the mesh was: v L; and, in the worst case, an actor that accelerates
    // during the latency (at rest at the capture, moving at the display) adds a L^2 / 2.
    m.motion_m = m.speed_mps * latency_s;
    if (options.worst_case_acceleration) {
      m.acceleration_mps2 = options.max_acceleration_mps2;
      m.motion_m += 0.5 * m.acceleration_mps2 * latency_s * latency_s;
    }
  }
  m.margin_m = options.floor_m + m.motion_m;
  if (m.margin_m > options.cap_m) {
    m.margin_m = options.cap_m;
    m.capped = true;
  }
  return m;
}

bool LatencyWindow::add(int64_t capture_ns, int64_t shown_ns) {
  const double s = 1e-9 * static_cast<double>(shown_ns - capture_ns);
  if (!(s >= 0) || s > 10) return false;
  samples_.push_back(s);
  while (samples_.size() > capacity_) samples_.pop_front();
  return true;
}

double LatencyWindow::latency_s() const {
  if (samples_.empty()) return 0;
  std::vector<double> sorted(samples_.begin(), samples_.end());
  std::sort(sorted.begin(), sorted.end());
  const size_t rank = static_cast<size_t>(std::ceil(quantile_ * sorted.size()));
  return sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1];
}

}  // namespace studio::projector

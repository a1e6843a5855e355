#include "projector/static_shift.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::projector {

Expected<void> SceneCacheOptions::validate() const {
  if (!(max_error_px > 0 && max_error_px <= 10))
    return fail("scene_cache.max_error_px: in (0, 10] projector pixels");
  if (!(settle_s >= 0 && settle_s <= 60)) return fail("scene_cache.settle_s: in [0, 60] seconds");
  if (hold_frames < 0 || hold_frames > 25) return fail("scene_cache.hold_frames: in [0, 25]");
  return {};
}

Expected<StaticShiftBound> StaticShiftBound::create(const ProjectorView& view,
                                                    const OffAxisOptions& off_axis) {
  if (auto ok = off_axis.validate(); !ok) return std::unexpected(ok.error());
  StaticShiftBound b;
  b.screen_ = view.screen();
  b.near_ = off_axis.near_m;
  // s_max: sigma_max of the Jacobian of pixel = dehom(H (s, t, 1)) over the rectangle:
  // J = (A - p b^T) / w with H = [A a; b^T c], w = b . (s, t) + c, p the pixel.
  const Eigen::Matrix3d& H = view.pixel_from_screen();
  constexpr int kGrid = 65;
  double worst = 0;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const Eigen::Vector3d st(b.screen_.width * i / (kGrid - 1),
                               b.screen_.height * j / (kGrid - 1), 1.0);
      const Eigen::Vector3d q = H * st;
      const Eigen::Vector2d p = q.head<2>() / q.z();
      const Eigen::Matrix2d J =
          (H.topLeftCorner<2, 2>() - p * H.block<1, 2>(2, 0)) / q.z();
      worst = std::max(worst, Eigen::JacobiSVD<Eigen::Matrix2d>(J).singularValues()(0));
    }
  b.scale_ = 1.01 * worst;
  return b;
}

namespace {
// f_max at one eye height: |h| / (h_e - h) at the ends of [lo, min(hi, h_e - near)] (eq. 1).
double f_at(const HeightRange& r, double h_e, double near) {
  double f = 0;
  const double hi = std::min(r.hi, h_e - near);
  if (hi > 0) f = std::max(f, hi / (h_e - hi));
  if (r.lo < 0) f = std::max(f, -r.lo / (h_e - r.lo));
  return f;
}
}  // namespace

double StaticShiftBound::shift_px(const HeightRange& heights, const Eigen::Vector3d& e0,
                                  const Eigen::Vector3d& e1) const {
  if (heights.hi < heights.lo) return 0;  // nothing static shown
  const double h0 = screen_.signed_distance(e0), h1 = screen_.signed_distance(e1);
  if (!(h0 > near_ && h1 > near_)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d d = e1 - e0;
  const double d_n = std::abs(d.dot(screen_.normal));
  const double d_t = (d - d.dot(screen_.normal) * screen_.normal).norm();
  double f = std::max(f_at(heights, h0, near_), f_at(heights, h1, near_));
  const double peak = heights.hi + near_;  // the capped form's largest f, if the move passes it
  if (peak > std::min(h0, h1) && peak < std::max(h0, h1))
    f = std::max(f, f_at(heights, peak, near_));
  double slope = 0;
  for (const Eigen::Vector3d& c : screen_.corners())
    for (const Eigen::Vector3d* e : {&e0, &e1}) {
      const Eigen::Vector3d v = c - *e;
      const double t = (v - v.dot(screen_.normal) * screen_.normal).norm();
      slope = std::max(slope, t / std::min(h0, h1));
    }
  return scale_ * f * (d_t + slope * d_n);
}

double StaticShiftBound::allowed_move_m(const HeightRange& heights, const Eigen::Vector3d& eye,
                                        double max_px) const {
  const double h = screen_.signed_distance(eye);
  if (!(h > near_)) return 0;
  const double f = f_at(heights, h, near_);
  if (f <= 0) return std::numeric_limits<double>::infinity();
  double slope = 0;
  for (const Eigen::Vector3d& c : screen_.corners()) {
    const Eigen::Vector3d v = c - eye;
    slope = std::max(slope, (v - v.dot(screen_.normal) * screen_.normal).norm() / h);
  }
  return max_px / (scale_ * f * std::sqrt(1 + slope * slope));
}

}  // namespace studio::projector

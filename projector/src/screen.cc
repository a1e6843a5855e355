#include "projector/screen.h"

#include <Eigen/Geometry>
#include <cmath>

#include "text.h"

namespace studio::projector {

Expected<void> ScreenOptions::validate() const {
  if (!(corner_tolerance_m >= 0) || !std::isfinite(corner_tolerance_m))
    return fail("screen: corner_tolerance_m must be finite and >= 0");
  if (!(min_edge_m > 0) || !std::isfinite(min_edge_m))
    return fail("screen: min_edge_m must be finite and > 0");
  return {};
}

Expected<Screen> Screen::from_corners(const std::array<Eigen::Vector3d, 4>& c,
                                      const ScreenOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  for (const Eigen::Vector3d& corner : c)
    if (!corner.allFinite()) return fail("screen: non-finite corner");
  const Eigen::Vector3d& ll = c[0];
  const Eigen::Vector3d& lr = c[1];
  const Eigen::Vector3d& ur = c[2];
  const Eigen::Vector3d& ul = c[3];
  const Eigen::Vector3d right = 0.5 * ((lr - ll) + (ur - ul));
  const Eigen::Vector3d up_raw = 0.5 * ((ul - ll) + (ur - lr));
  if (!(right.norm() >= options.min_edge_m))
    return fail(
        text("screen: degenerate corners: width %.4g m (collinear or coincident)", right.norm()));
  Screen s;
  s.right = right.normalized();
  const Eigen::Vector3d up = up_raw - s.right * s.right.dot(up_raw);
  if (!(up.norm() >= options.min_edge_m))
    return fail(
        text("screen: degenerate corners: height %.4g m (collinear or coincident)", up.norm()));
  s.up = up.normalized();
  s.normal = s.right.cross(s.up);
  s.width = right.norm();
  s.height = up.norm();
  const Eigen::Vector3d centre = 0.25 * (ll + lr + ur + ul);
  s.origin = centre - 0.5 * s.width * s.right - 0.5 * s.height * s.up;
  const std::array<Eigen::Vector3d, 4> fitted = s.corners();
  static constexpr const char* kNames[4] = {"lower-left", "lower-right", "upper-right",
                                            "upper-left"};
  for (int i = 0; i < 4; ++i) {
    const double off = (fitted[i] - c[i]).norm();
    if (off > options.corner_tolerance_m) {
      return fail(text(
          "screen: the %s corner is %.1f mm from the fitted rectangle (tolerance %.1f mm): the "
          "corners are not a planar rectangle in the order lower-left, lower-right, upper-right, "
          "upper-left",
          kNames[i], 1e3 * off, 1e3 * options.corner_tolerance_m));
    }
  }
  return s;
}

std::array<Eigen::Vector3d, 4> Screen::corners() const {
  return {origin, origin + width * right, origin + width * right + height * up,
          origin + height * up};
}

}  // namespace studio::projector

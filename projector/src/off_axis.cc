#include "projector/off_axis.h"

#include <cmath>

#include "text.h"

namespace studio::projector {

Expected<void> OffAxisOptions::validate() const {
  if (!(near_m > 0) || !std::isfinite(near_m))
    return fail("off-axis: near_m must be finite and > 0");
  if (!(far_m > near_m) || !std::isfinite(far_m))
    return fail("off-axis: far_m must be finite and > near_m");
  if (!(min_eye_distance_m > 0) || !std::isfinite(min_eye_distance_m))
    return fail("off-axis: min_eye_distance_m must be finite and > 0");
  return {};
}

Eigen::Matrix4d frustum(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * n / (r - l);
  m(0, 2) = (r + l) / (r - l);
  m(1, 1) = 2 * n / (t - b);
  m(1, 2) = (t + b) / (t - b);
  m(2, 2) = -(f + n) / (f - n);
  m(2, 3) = -2 * f * n / (f - n);
  m(3, 2) = -1;
  return m;
}

Expected<OffAxisView> off_axis_view(const Screen& screen, const Eigen::Vector3d& eye,
                                    const OffAxisOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  if (!eye.allFinite()) return fail("off-axis: non-finite eye position");
  const std::array<Eigen::Vector3d, 4> c = screen.corners();
  const Eigen::Vector3d va = c[0] - eye, vb = c[1] - eye, vc = c[3] - eye;
  OffAxisView view;
  view.eye = eye;
  view.distance = -va.dot(screen.normal);
  if (!(view.distance >= options.min_eye_distance_m)) {
    return fail(
        text("off-axis: the eye (%.3f, %.3f, %.3f) is %.3f m %s the screen plane (it must be at "
             "least %.3f m in front)",
             eye.x(), eye.y(), eye.z(), std::abs(view.distance),
             view.distance < 0 ? "behind" : "in front of", options.min_eye_distance_m));
  }
  const double n = options.near_m, f = options.far_m, scale = n / view.distance;
  view.left = screen.right.dot(va) * scale;
  view.right = screen.right.dot(vb) * scale;
  view.bottom = screen.up.dot(va) * scale;
  view.top = screen.up.dot(vc) * scale;
  view.near = n;
  view.far = f;
  Eigen::Matrix4d rotation = Eigen::Matrix4d::Identity();
  rotation.block<1, 3>(0, 0) = screen.right.transpose();
  rotation.block<1, 3>(1, 0) = screen.up.transpose();
  rotation.block<1, 3>(2, 0) = screen.normal.transpose();
  Eigen::Matrix4d translation = Eigen::Matrix4d::Identity();
  translation.block<3, 1>(0, 3) = -eye;
  view.view_from_world = rotation * translation;
  view.clip_from_view = frustum(view.left, view.right, view.bottom, view.top, n, f);
  view.clip_from_world = view.clip_from_view * view.view_from_world;
  return view;
}

}  // namespace studio::projector

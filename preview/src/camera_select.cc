#include "preview/camera_select.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace studio::preview {

Eigen::Vector3d bounds_centre(const std::vector<Eigen::Vector3f>& points) {
  if (points.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3f lo = points[0], hi = lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (0.5f * (lo + hi)).cast<double>();
}

Expected<void> BlendOptions::validate() const {
  if (cameras < 1 || cameras > 8) return fail("blend cameras: expected 1..8");
  return {};
}

double view_angle(const Eigen::Vector3d& eye, const Eigen::Vector3d& centre,
                  const Eigen::Vector3d& target) {
  const Eigen::Vector3d a = eye - target, b = centre - target;
  if (a.norm() < 1e-12 || b.norm() < 1e-12) return std::numbers::pi;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

namespace {

std::vector<CameraWeight> by_angle(const std::vector<StudioCameraPose>& cameras,
                                   const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  std::vector<CameraWeight> out;
  for (int i = 0; i < static_cast<int>(cameras.size()); ++i)
    out.push_back({i, view_angle(eye, cameras[i].centre, target), 0});
  std::stable_sort(out.begin(), out.end(),
                   [](const CameraWeight& a, const CameraWeight& b) { return a.angle < b.angle; });
  return out;
}

}  // namespace

std::vector<CameraWeight> nearest(const std::vector<StudioCameraPose>& cameras,
                                  const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  auto all = by_angle(cameras, eye, target);
  if (all.empty()) return all;
  all.resize(1);
  all[0].weight = 1;
  return all;
}

double blend_threshold(const std::vector<StudioCameraPose>& cameras, const Eigen::Vector3d& eye,
                       const Eigen::Vector3d& target, const BlendOptions& options) {
  const auto all = by_angle(cameras, eye, target);
  const std::size_t k = std::max(0, options.cameras);
  // The (k+1)-th camera's angle; with only k cameras, pi (behind the actor).
  return all.size() > k ? all[k].angle : std::numbers::pi;
}

std::vector<CameraWeight> blend(const std::vector<StudioCameraPose>& cameras,
                                const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                const BlendOptions& options) {
  auto all = by_angle(cameras, eye, target);
  if (all.empty()) return all;
  const std::size_t k = std::min<std::size_t>(options.cameras, all.size());
  constexpr double kExact = 1e-9;  // a camera exactly at the eye's direction
  if (all[0].angle < kExact) {
    all.resize(1);
    all[0].weight = 1;
    return all;
  }
  const double thr = blend_threshold(cameras, eye, target, options);
  std::vector<CameraWeight> out;
  double sum = 0;
  for (std::size_t i = 0; i < k; ++i) {
    CameraWeight w = all[i];
    w.weight = thr > w.angle ? (1 - w.angle / thr) / w.angle : 0;
    if (w.weight <= 0) continue;
    sum += w.weight;
    out.push_back(w);
  }
  if (out.empty()) {  // k cameras all at the threshold: the nearest alone
    all.resize(1);
    all[0].weight = 1;
    return all;
  }
  for (auto& w : out) w.weight /= sum;
  return out;
}

}  // namespace studio::preview

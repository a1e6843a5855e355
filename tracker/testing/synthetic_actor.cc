#include "testing/synthetic_actor.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace studio::tracker::testing {
namespace {

void add_shape(OccupancyGrid& grid, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
               const std::function<bool(const Eigen::Vector3d&)>& inside) {
  constexpr int kS = 4;
  const Eigen::Vector3i vlo =
      grid.voxel_coords(lo).array().floor().cast<int>().matrix().cwiseMax(0);
  const Eigen::Vector3i vhi =
      grid.voxel_coords(hi).array().ceil().cast<int>().matrix().cwiseMin(grid.dims());
  for (int x = vlo.x(); x < vhi.x(); ++x)
    for (int z = vlo.z(); z < vhi.z(); ++z)
      for (int y = vlo.y(); y < vhi.y(); ++y) {
        int hits = 0;
        for (int i = 0; i < kS; ++i)
          for (int j = 0; j < kS; ++j)
            for (int k = 0; k < kS; ++k) {
              const Eigen::Vector3d v(x + (i + 0.5) / kS, y + (j + 0.5) / kS, z + (k + 0.5) / kS);
              hits += inside(grid.point(v));
            }
        const uint8_t f =
            uint8_t(std::lround(double(hits) * OccupancyGrid::kFull / (kS * kS * kS)));
        grid.at(x, y, z) = std::max(grid.at(x, y, z), f);
      }
}

}  // namespace

void add_sphere(OccupancyGrid& grid, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d e = Eigen::Vector3d::Constant(r);
  add_shape(grid, c - e, c + e,
            [&](const Eigen::Vector3d& p) { return (p - c).squaredNorm() < r * r; });
}

void add_capsule(OccupancyGrid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 double r) {
  const Eigen::Vector3d e = Eigen::Vector3d::Constant(r);
  const Eigen::Vector3d ab = b - a;
  const double len2 = std::max(ab.squaredNorm(), 1e-12);
  add_shape(grid, a.cwiseMin(b) - e, a.cwiseMax(b) + e, [&](const Eigen::Vector3d& p) {
    const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
    return (p - (a + t * ab)).squaredNorm() < r * r;
  });
}

void add_box(OccupancyGrid& grid, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  add_shape(grid, lo, hi, [&](const Eigen::Vector3d& p) {
    return (p.array() >= lo.array()).all() && (p.array() < hi.array()).all();
  });
}

namespace {

// Body point (x right, y up, z forward, relative to the feet) → studio frame, with crouch.
struct Pose {
  const SyntheticActor& a;
  Eigen::Vector3d operator()(double x, double y, double z) const {
    const double s = a.height / 1.75;
    // Crouching lowers everything above the knees (y > 0.5) rigidly by up to 0.6 m (scaled);
    // the thighs shorten in between.
    double yy = y * s;
    const double knee = 0.5 * s;
    if (yy > knee) yy -= 0.6 * s * a.crouch * std::min(1.0, (yy - knee) / (0.45 * s));
    const double c = std::cos(a.yaw), sn = std::sin(a.yaw);
    return {a.floor_xz.x() + c * x * s + sn * z * s, yy, a.floor_xz.y() - sn * x * s + c * z * s};
  }
};

}  // namespace

Eigen::Vector3d SyntheticActor::head_centre() const {
  return Pose{*this}(0, 1.75 - head_radius * 1.75 / height, 0);
}

Eigen::Vector3d SyntheticActor::raised_hand_centre() const { return Pose{*this}(0.2, 2.02, 0.02); }

void add_actor(OccupancyGrid& g, const SyntheticActor& a) {
  const Pose P{a};
  const double s = a.height / 1.75;
  add_sphere(g, a.head_centre(), a.head_radius);
  add_capsule(g, P(0, 1.55, 0), P(0, 1.42, 0), 0.055 * s);         // neck
  add_capsule(g, P(-0.07, 0.98, 0), P(-0.07, 1.34, 0), 0.11 * s);  // torso (0.36 x 0.22)
  add_capsule(g, P(0.07, 0.98, 0), P(0.07, 1.34, 0), 0.11 * s);
  add_capsule(g, P(-0.17, 1.42, 0), P(0.17, 1.42, 0), 0.065 * s);     // shoulders
  add_capsule(g, P(-0.2, 1.42, 0), P(-0.24, 0.82, 0.02), 0.045 * s);  // left arm
  if (a.hand_raised) {
    add_capsule(g, P(0.2, 1.42, 0), P(0.2, 1.98, 0.02), 0.045 * s);  // right arm, up
    add_sphere(g, a.raised_hand_centre(), 0.05 * s);                 // right hand
  } else {
    add_capsule(g, P(0.2, 1.42, 0), P(0.24, 0.82, 0.02), 0.045 * s);
  }
  add_capsule(g, P(-0.1, 0.95, 0), P(-0.11, 0.05, 0.02), 0.07 * s);  // legs
  add_capsule(g, P(0.1, 0.95, 0), P(0.11, 0.05, 0.02), 0.07 * s);
}

}  // namespace studio::tracker::testing

#pragma once
// Synthetic scenes for hull tests and benchmarks: analytic solids (ellipsoids, boxes) and exact
// masks rendered by casting every pixel centre's ray (distortion included, through
// Camera::pixel_ray_in_world). Not part of the library. Cameras by look-at and camera rings are
// the shared test helpers' (tests/support: support/cameras.h).

#include <Eigen/Core>
#include <random>
#include <vector>

#include "core/camera.h"
#include "core/run_mask.h"

namespace studio::hull::testing {

struct Ellipsoid {
  Eigen::Vector3d centre;
  Eigen::Vector3d radii;
};
struct Box3 {
  Eigen::Vector3d min, max;
};

struct Scene {
  std::vector<Ellipsoid> ellipsoids;
  std::vector<Box3> boxes;
  bool inside(const Eigen::Vector3d& x) const;
  bool ray_hits(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // Points on the surface of the union (samples on each solid's surface not inside another).
  std::vector<Eigen::Vector3d> surface_samples(int per_solid, std::mt19937& rng) const;
  double volume_estimate(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) const;
};

RunMask render_mask(const Camera& camera, const Scene& scene);

// A standing figure about 1.8 m tall made of ellipsoids, feet on the floor at (x, 0, z).
Scene actor(double x = 0, double z = 0);

}  // namespace studio::hull::testing

#include "testing/synthetic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace studio::hull::testing {

namespace {
bool in_ellipsoid(const Ellipsoid& e, const Eigen::Vector3d& x) {
  return ((x - e.centre).array() / e.radii.array()).square().sum() <= 1.0;
}
bool in_box(const Box3& b, const Eigen::Vector3d& x) {
  return (x.array() >= b.min.array()).all() && (x.array() <= b.max.array()).all();
}
}  // namespace

bool Scene::inside(const Eigen::Vector3d& x) const {
  for (const auto& e : ellipsoids) if (in_ellipsoid(e, x)) return true;
  for (const auto& b : boxes) if (in_box(b, x)) return true;
  return false;
}

bool Scene::ray_hits(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  for (const auto& e : ellipsoids) {
    const Eigen::Vector3d oo = (o - e.centre).array() / e.radii.array();
    const Eigen::Vector3d dd = d.array() / e.radii.array();
    const double a = dd.squaredNorm(), b = oo.dot(dd), c = oo.squaredNorm() - 1;
    const double disc = b * b - a * c;
    if (disc >= 0 && (-b + std::sqrt(disc)) >= 0) return true;
  }
  for (const auto& bx : boxes) {
    double t0 = 0, t1 = 1e300;
    bool hit = true;
    for (int k = 0; k < 3 && hit; ++k) {
      if (d[k] == 0) {
        hit = o[k] >= bx.min[k] && o[k] <= bx.max[k];
        continue;
      }
      double a = (bx.min[k] - o[k]) / d[k], b = (bx.max[k] - o[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a), t1 = std::min(t1, b);
      hit = t0 <= t1;
    }
    if (hit) return true;
  }
  return false;
}

std::vector<Eigen::Vector3d> Scene::surface_samples(int per_solid, std::mt19937& rng) const {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01;
  std::vector<Eigen::Vector3d> out;
  const auto keep = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& outward) {
    if (!inside(p + 1e-9 * outward)) out.push_back(p);
  };
  for (const auto& e : ellipsoids) {
    for (int k = 0; k < per_solid; ++k) {
      Eigen::Vector3d g(n01(rng), n01(rng), n01(rng));
      g.normalize();
      keep(e.centre + e.radii.cwiseProduct(g), g.cwiseQuotient(e.radii));
    }
  }
  for (const auto& b : boxes) {
    for (int k = 0; k < per_solid; ++k) {
      const int face = k % 6, ax = face / 2;
      Eigen::Vector3d p;
      for (int q = 0; q < 3; ++q) p[q] = b.min[q] + u01(rng) * (b.max[q] - b.min[q]);
      p[ax] = face % 2 ? b.max[ax] : b.min[ax];
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[ax] = face % 2 ? 1 : -1;
      keep(p, n);
    }
  }
  return out;
}

double Scene::volume_estimate(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) const {
  const Eigen::Vector3d step = (hi - lo) / n;
  long count = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        count += inside(lo + step.cwiseProduct(Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5)));
  return count * step.prod();
}

RunMask render_mask(const Camera& camera, const Scene& scene) {
  RunMask m(camera.width, camera.height);
  const Eigen::Vector3d o = camera.centre_in_world();
  for (int y = 0; y < camera.height; ++y) {
    int begin = -1;
    for (int x = 0; x <= camera.width; ++x) {
      const bool hit =
          x < camera.width && scene.ray_hits(o, camera.pixel_ray_in_world(Eigen::Vector2d(x, y)));
      if (hit && begin < 0) begin = x;
      if (!hit && begin >= 0) {
        m.push_run(y, begin, x);
        begin = -1;
      }
    }
  }
  m.finish();
  return m;
}

Scene actor(double x, double z) {
  Scene s;
  const Eigen::Vector3d p(x, 0, z);
  const auto add = [&](double cx, double cy, double cz, double rx, double ry, double rz) {
    s.ellipsoids.push_back({p + Eigen::Vector3d(cx, cy, cz), Eigen::Vector3d(rx, ry, rz)});
  };
  add(0, 1.65, 0, 0.1, 0.12, 0.11);       // head
  add(0, 1.25, 0, 0.2, 0.3, 0.12);        // torso
  add(0, 0.95, 0, 0.17, 0.12, 0.11);      // hips
  add(-0.09, 0.47, 0, 0.07, 0.45, 0.07);  // legs
  add(0.09, 0.47, 0.05, 0.07, 0.45, 0.07);
  add(-0.38, 1.38, 0, 0.22, 0.05, 0.05);  // arms
  add(0.3, 1.15, 0.1, 0.05, 0.28, 0.05);
  add(-0.09, 0.04, 0.06, 0.05, 0.04, 0.12);  // feet
  add(0.09, 0.04, 0.11, 0.05, 0.04, 0.12);
  return s;
}

}  // namespace studio::hull::testing

// Geometry of the analytic body parts and of their union (sim/actor.h).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "sim/actor.h"

namespace studio::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Two unit vectors completing e (unit) to an orthonormal basis.
void basis(const Eigen::Vector3d& e, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  const Eigen::Vector3d helper =
      std::abs(e.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  *e1 = e.cross(helper).normalized();
  *e2 = e.cross(*e1);
}

// Roots of A t^2 + 2 B t + C = 0 in increasing order; false if none.
bool roots(double A, double B, double C, double* t0, double* t1) {
  if (A <= 0) return false;
  const double disc = B * B - A * C;
  if (disc < 0) return false;
  const double s = std::sqrt(disc);
  *t0 = (-B - s) / A;
  *t1 = (-B + s) / A;
  return true;
}

}  // namespace

bool Part::inside(const Eigen::Vector3d& x) const {
  if (shape == PartShape::capsule) {
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double h = len2 > 0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (x - a - h * ab).squaredNorm() <= radius * radius;
  }
  const Eigen::Vector3d u = (axes.transpose() * (x - centre)).cwiseQuotient(radii);
  return u.squaredNorm() <= 1.0;
}

std::optional<double> Part::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                      double t_min) const {
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](double t) {
    if (t > t_min && t < best) best = t;
  };
  if (shape == PartShape::ellipsoid) {
    const Eigen::Vector3d o2 = (axes.transpose() * (o - centre)).cwiseQuotient(radii);
    const Eigen::Vector3d d2 = (axes.transpose() * d).cwiseQuotient(radii);
    double t0, t1;
    if (roots(d2.squaredNorm(), o2.dot(d2), o2.squaredNorm() - 1.0, &t0, &t1)) {
      consider(t0);
      if (!(best < std::numeric_limits<double>::infinity())) consider(t1);
    }
  } else {
    const Eigen::Vector3d ab = b - a;
    const double len = ab.norm();
    const Eigen::Vector3d e = len > 0 ? Eigen::Vector3d(ab / len) : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d oa = o - a;
    const double oe = oa.dot(e), de = d.dot(e);
    const Eigen::Vector3d op = oa - oe * e, dp = d - de * e;
    double t0, t1;
    // Cylinder body, valid where the axial coordinate lies in [0, len].
    if (roots(dp.squaredNorm(), op.dot(dp), op.squaredNorm() - radius * radius, &t0, &t1)) {
      for (double t : {t0, t1}) {
        const double axial = oe + t * de;
        if (axial >= 0 && axial <= len) consider(t);
      }
    }
    // End spheres, valid beyond the ends.
    for (int end = 0; end < 2; ++end) {
      const Eigen::Vector3d oc = end == 0 ? oa : Eigen::Vector3d(o - b);
      if (roots(d.squaredNorm(), oc.dot(d), oc.squaredNorm() - radius * radius, &t0, &t1)) {
        for (double t : {t0, t1}) {
          const double axial = oe + t * de;
          if (end == 0 ? axial <= 0 : axial >= len) consider(t);
        }
      }
    }
  }
  if (best < std::numeric_limits<double>::infinity()) return best;
  return std::nullopt;
}

Eigen::Vector3d Part::normal(const Eigen::Vector3d& p) const {
  if (shape == PartShape::capsule) {
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double h = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (p - a - h * ab).normalized();
  }
  const Eigen::Vector3d u = (axes.transpose() * (p - centre)).cwiseQuotient(radii.cwiseAbs2());
  return (axes * u).normalized();
}

void Part::bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const {
  if (shape == PartShape::capsule) {
    *lo = a.cwiseMin(b).array() - radius;
    *hi = a.cwiseMax(b).array() + radius;
    return;
  }
  // Half extent along world axis i: sqrt(sum_j (axes_ij radii_j)^2).
  const Eigen::Vector3d half = (axes * radii.asDiagonal()).rowwise().norm();
  *lo = centre - half;
  *hi = centre + half;
}

double Part::surface_area() const {
  if (shape == PartShape::capsule) {
    return 2 * kPi * radius * (b - a).norm() + 4 * kPi * radius * radius;
  }
  constexpr double p = 1.6075;  // Knud Thomsen's approximation, < 1.1 % error
  const double ap = std::pow(radii.x(), p), bp = std::pow(radii.y(), p),
               cp = std::pow(radii.z(), p);
  return 4 * kPi * std::pow((ap * bp + ap * cp + bp * cp) / 3.0, 1.0 / p);
}

Eigen::Vector3d Part::surface_point(double u1, double u2) const {
  const double phi = 2 * kPi * u2;
  if (shape == PartShape::ellipsoid) {
    const double z = 1 - 2 * u1, s = std::sqrt(std::max(0.0, 1 - z * z));
    const Eigen::Vector3d u(s * std::cos(phi), s * std::sin(phi), z);
    return centre + axes * radii.cwiseProduct(u);
  }
  const Eigen::Vector3d ab = b - a;
  const double len = ab.norm();
  const Eigen::Vector3d e = len > 0 ? Eigen::Vector3d(ab / len) : Eigen::Vector3d::UnitY();
  Eigen::Vector3d e1, e2;
  basis(e, &e1, &e2);
  const double body = 2 * kPi * radius * len, caps = 4 * kPi * radius * radius;
  const double frac = body / (body + caps);
  if (u1 < frac) {
    const double axial = u1 / frac * len;
    return a + axial * e + radius * (std::cos(phi) * e1 + std::sin(phi) * e2);
  }
  const double z = 1 - 2 * (u1 - frac) / (1 - frac), s = std::sqrt(std::max(0.0, 1 - z * z));
  const Eigen::Vector3d w = s * std::cos(phi) * e1 + s * std::sin(phi) * e2 + z * e;
  return (z >= 0 ? b : a) + radius * w;
}

bool ActorBody::inside(const Eigen::Vector3d& x) const {
  for (const Part& p : parts) {
    if (p.inside(x)) return true;
  }
  return false;
}

std::optional<RayHit> ActorBody::ray_hit(const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& direction) const {
  std::optional<RayHit> hit;
  for (int i = 0; i < static_cast<int>(parts.size()); ++i) {
    const auto t = parts[i].intersect(origin, direction);
    if (t && (!hit || *t < hit->t)) {
      hit = RayHit{*t, origin + *t * direction, Eigen::Vector3d::Zero(), i};
    }
  }
  if (hit) hit->normal = parts[hit->part].normal(hit->point);
  return hit;
}

std::vector<Eigen::Vector3d> ActorBody::surface_samples(int n, uint64_t seed) const {
  std::vector<Eigen::Vector3d> out;
  if (n <= 0 || parts.empty()) return out;
  out.reserve(n);
  std::vector<double> cumulative;
  double total = 0;
  for (const Part& p : parts) cumulative.push_back(total += p.surface_area());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const int max_tries = 200 * n + 1000;
  for (int tries = 0; static_cast<int>(out.size()) < n && tries < max_tries; ++tries) {
    const double pick = uni(rng) * total;
    const int i = static_cast<int>(std::lower_bound(cumulative.begin(), cumulative.end(), pick) -
                                   cumulative.begin());
    const Part& part = parts[std::min<int>(i, parts.size() - 1)];
    const double u1 = uni(rng), u2 = uni(rng);
    if (part.shape == PartShape::ellipsoid) {
      // Area-uniform by rejection: the map u -> axes * diag(r) * u stretches the sphere's area
      // element by r0 r1 r2 |diag(r)^-1 u|.
      const double z = 1 - 2 * u1, s = std::sqrt(std::max(0.0, 1 - z * z));
      const Eigen::Vector3d u(s * std::cos(2 * kPi * u2), s * std::sin(2 * kPi * u2), z);
      const double stretch = u.cwiseQuotient(part.radii).norm() * part.radii.minCoeff();
      if (uni(rng) > stretch) continue;
    }
    const Eigen::Vector3d x = part.surface_point(u1, u2);
    bool covered = false;
    for (const Part& other : parts) {
      if (&other != &part && other.inside(x)) {
        covered = true;
        break;
      }
    }
    if (!covered) out.push_back(x);
  }
  return out;
}

void ActorBody::bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const {
  lo->setConstant(std::numeric_limits<double>::infinity());
  hi->setConstant(-std::numeric_limits<double>::infinity());
  for (const Part& p : parts) {
    Eigen::Vector3d l, h;
    p.bounds(&l, &h);
    *lo = lo->cwiseMin(l);
    *hi = hi->cwiseMax(h);
  }
}

TriangleMesh ActorBody::mesh(int segments) const {
  segments = std::max(segments, 4);
  const int rings = segments / 2 * 2;  // even, so capsules split at the equator
  TriangleMesh mesh;
  for (const Part& p : parts) {
    const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
    Eigen::Vector3d e = Eigen::Vector3d::UnitZ(), e1 = Eigen::Vector3d::UnitX(),
                    e2 = Eigen::Vector3d::UnitY();
    if (p.shape == PartShape::capsule) {
      const Eigen::Vector3d ab = p.b - p.a;
      if (ab.norm() > 0) e = ab.normalized();
      basis(e, &e1, &e2);
    }
    // Latitude rings from the south pole to the north pole; a capsule gets the equator twice
    // (once at each end) so the cylinder body is the quad strip between them.
    std::vector<std::pair<double, int>> lats;  // (latitude, which end: 0 a, 1 b)
    for (int k = 0; k <= rings; ++k) {
      const double lat = -kPi / 2 + kPi * k / rings;
      if (p.shape == PartShape::capsule && k == rings / 2) {
        lats.push_back({lat, 0});
        lats.push_back({lat, 1});
      } else {
        lats.push_back({lat, k > rings / 2 ? 1 : 0});
      }
    }
    for (const auto& [lat, end] : lats) {
      for (int j = 0; j < segments; ++j) {
        const double lon = 2 * kPi * j / segments;
        const Eigen::Vector3d u(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon),
                                std::sin(lat));
        Eigen::Vector3d x;
        if (p.shape == PartShape::ellipsoid) {
          x = p.centre + p.axes * p.radii.cwiseProduct(u);
        } else {
          x = (end ? p.b : p.a) + p.radius * (u.x() * e1 + u.y() * e2 + u.z() * e);
        }
        mesh.vertices.push_back(x.cast<float>());
      }
    }
    const int nl = static_cast<int>(lats.size());
    for (int k = 0; k + 1 < nl; ++k) {
      for (int j = 0; j < segments; ++j) {
        const uint32_t i00 = base + k * segments + j, i01 = base + k * segments + (j + 1) % segments;
        const uint32_t i10 = i00 + segments, i11 = i01 + segments;
        // (e1, e2, e) is right-handed, longitude grows counter-clockwise about e: outward CCW.
        mesh.triangles.push_back({i00, i01, i11});
        mesh.triangles.push_back({i00, i11, i10});
      }
    }
  }
  return mesh;
}

}  // namespace studio::sim

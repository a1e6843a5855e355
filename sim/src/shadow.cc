// The actor's soft floor shadow (sim/studio.h): the per-instant shadow map over the floor and
// its application to a camera's floor pixels (render.cc draws the actor over it).
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "studio_impl.h"

namespace studio::sim::detail {

Rect shadow_rect(const CameraCache& cam, const ShadowMap& shadow) {
  if (shadow.empty()) return {};
  const double xs[2] = {shadow.x0, shadow.x0 + (shadow.nx - 1) * shadow.cell};
  const double zs[2] = {shadow.z0, shadow.z0 + (shadow.nz - 1) * shadow.cell};
  Eigen::Vector3d corners[4];
  for (int k = 0; k < 4; ++k)
    corners[k] = cam.R * Eigen::Vector3d(xs[k & 1], 0, zs[k >> 1]) + cam.t;
  return cam.project_hull(corners, 4, 1);
}

namespace {

// Pinhole cameras: the pixels [x0, x1) of row y whose floor point may lie on the shadow map's box,
// within [r.x0, r.x1). Along a row the world ray is affine in u, w(u) = w0 + u w1, and its floor
// point C - (C.y / w.y) w (w.y < 0) has x >= bx iff (C.x - bx) w.y - C.y w.x <= 0: every bound of
// the box is a half-line in u. The span is widened by 2 px, far beyond rounding, so the pixels
// left out are off the map, where ShadowMap::at is 1 and the pixel unchanged.
std::pair<int, int> shadow_span(const CameraCache& cam, const ShadowMap& shadow, const Rect& r,
                                int y) {
  const auto& k = cam.camera.intrinsics;
  const double yv = (y - k.cy) / k.fy;
  const Eigen::Matrix3d Rt = cam.R.transpose();
  const Eigen::Vector3d w0 = Rt * Eigen::Vector3d((-k.cx - k.skew * yv) / k.fx, yv, 1.0);
  const Eigen::Vector3d w1 = Rt * Eigen::Vector3d(1.0 / k.fx, 0, 0);
  const Eigen::Vector3d& C = cam.centre;
  double lo = -1e300, hi = 1e300;
  // Keep u where a + b u <= 0.
  auto keep = [&](double a, double b) {
    if (std::abs(b) < 1e-15) {
      if (a > 1e-9) lo = 1e300;  // nowhere
      return;
    }
    if (b > 0)
      hi = std::min(hi, -a / b);
    else
      lo = std::max(lo, -a / b);
  };
  keep(w0.y(), w1.y());  // w.y < 0: the ray goes down
  const double bx[2] = {shadow.x0, shadow.x0 + (shadow.nx - 1) * shadow.cell};
  const double bz[2] = {shadow.z0, shadow.z0 + (shadow.nz - 1) * shadow.cell};
  keep((C.x() - bx[0]) * w0.y() - C.y() * w0.x(), (C.x() - bx[0]) * w1.y() - C.y() * w1.x());
  keep(-((C.x() - bx[1]) * w0.y() - C.y() * w0.x()), -((C.x() - bx[1]) * w1.y() - C.y() * w1.x()));
  keep((C.z() - bz[0]) * w0.y() - C.y() * w0.z(), (C.z() - bz[0]) * w1.y() - C.y() * w1.z());
  keep(-((C.z() - bz[1]) * w0.y() - C.y() * w0.z()), -((C.z() - bz[1]) * w1.y() - C.y() * w1.z()));
  if (!(lo <= hi)) return {r.x0, r.x0};
  const double x0 = std::max<double>(r.x0, std::floor(lo) - 2);
  const double x1 = std::min<double>(r.x1, std::ceil(hi) + 3);
  return {static_cast<int>(x0), std::max(static_cast<int>(x0), static_cast<int>(x1))};
}

}  // namespace

// `cull`: visit only shadow_span() of each row (pinhole cameras); same pixels changed.
void apply_shadow(const CameraCache& cam, const ShadowMap& shadow, Image<Rgb8>* image, bool cull) {
  if (shadow.empty()) return;
  const Rect r = shadow_rect(cam, shadow);
  const int W = cam.camera.width;
  for (int y = r.y0; y < r.y1; ++y) {
    const uint8_t* surf = &cam.surface(0, y);
    const Eigen::Vector2d* floor = cam.floor_xz.data() + static_cast<std::size_t>(y) * W;
    Rgb8* row = &(*image)(0, y);
    const auto [x0, x1] = cull ? shadow_span(cam, shadow, r, y) : std::pair{r.x0, r.x1};
    for (int x = x0; x < x1; ++x) {
      if (surf[x] != kFloor) continue;
      const float f = shadow.at(floor[x].x(), floor[x].y());  // 1 off the map (and for NaN)
      if (f >= 1.0f) continue;
      row[x].r = static_cast<uint8_t>(row[x].r * f + 0.5f);
      row[x].g = static_cast<uint8_t>(row[x].g * f + 0.5f);
      row[x].b = static_cast<uint8_t>(row[x].b * f + 0.5f);
    }
  }
}

float ShadowMap::at(double x, double z) const {
  const double fx = (x - x0) / cell, fz = (z - z0) / cell;
  if (!(fx >= 0 && fz >= 0 && fx <= nx - 1 && fz <= nz - 1)) return 1.0f;
  const int ix = std::min(static_cast<int>(fx), nx - 2),
            iz = std::min(static_cast<int>(fz), nz - 2);
  const float ax = static_cast<float>(fx - ix), az = static_cast<float>(fz - iz);
  const float* f0 = &factor[static_cast<std::size_t>(iz) * nx + ix];
  const float* f1 = f0 + nx;
  return (f0[0] * (1 - ax) + f0[1] * ax) * (1 - az) + (f1[0] * (1 - ax) + f1[1] * ax) * az;
}

ShadowMap make_shadow(const ActorBody& body, double strength) {
  ShadowMap map;
  if (strength <= 0 || body.parts.empty()) return map;
  struct Footprint {
    Eigen::Vector2d p, q;
    double r, w, density;
  };
  const Eigen::Vector3d& L = kKeyLight;
  auto floor_of = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d f = x - (x.y() / L.y()) * L;
    return Eigen::Vector2d(f.x(), f.z());
  };
  std::vector<Footprint> prints;
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const Part& part : body.parts) {
    Eigen::Vector3d p, q;
    double r;
    if (part.shape == PartShape::capsule) {
      p = part.a;
      q = part.b;
      r = part.radius;
    } else {
      int i;
      part.radii.maxCoeff(&i);
      r = (part.radii.sum() - part.radii[i]) / 2;
      const Eigen::Vector3d half = part.axes.col(i) * std::max(0.0, part.radii[i] - r);
      p = part.centre - half;
      q = part.centre + half;
    }
    const double h = std::max(0.0, 0.5 * (p.y() + q.y()));
    Footprint f{floor_of(p), floor_of(q), r, 0.02 + 0.10 * h, std::max(0.3, 1.0 - 0.2 * h)};
    lo = lo.cwiseMin((f.p.cwiseMin(f.q).array() - (f.r + f.w)).matrix());
    hi = hi.cwiseMax((f.p.cwiseMax(f.q).array() + (f.r + f.w)).matrix());
    prints.push_back(f);
  }
  map.cell = 0.04;
  map.x0 = lo.x();
  map.z0 = lo.y();
  map.nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / map.cell)) + 2;
  map.nz = static_cast<int>(std::ceil((hi.y() - lo.y()) / map.cell)) + 2;
  std::vector<float> occlusion(static_cast<std::size_t>(map.nx) * map.nz, 0.0f);
  for (const Footprint& f : prints) {
    const Eigen::Vector2d flo = f.p.cwiseMin(f.q).array() - (f.r + f.w);
    const Eigen::Vector2d fhi = f.p.cwiseMax(f.q).array() + (f.r + f.w);
    const int i0 = std::max(0, static_cast<int>((flo.x() - map.x0) / map.cell));
    const int i1 = std::min(map.nx - 1, static_cast<int>((fhi.x() - map.x0) / map.cell) + 1);
    const int j0 = std::max(0, static_cast<int>((flo.y() - map.z0) / map.cell));
    const int j1 = std::min(map.nz - 1, static_cast<int>((fhi.y() - map.z0) / map.cell) + 1);
    const Eigen::Vector2d pq = f.q - f.p;
    const double pq2 = std::max(pq.squaredNorm(), 1e-12);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Eigen::Vector2d x(map.x0 + i * map.cell, map.z0 + j * map.cell);
        const double h = std::clamp((x - f.p).dot(pq) / pq2, 0.0, 1.0);
        const double dist = (x - f.p - h * pq).norm();
        const double s = std::clamp((f.r + f.w - dist) / (2 * f.w), 0.0, 1.0);
        const float c = static_cast<float>(s * s * (3 - 2 * s) * f.density);
        float& o = occlusion[static_cast<std::size_t>(j) * map.nx + i];
        o = std::max(o, c);
      }
    }
  }
  map.factor.resize(occlusion.size());
  for (std::size_t k = 0; k < occlusion.size(); ++k) {
    map.factor[k] = 1.0f - static_cast<float>(strength) * occlusion[k];
  }
  return map;
}

}  // namespace studio::sim::detail

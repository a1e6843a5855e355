// The per-frame hot path of the simulated studio: floor shadow, actor ray casting inside the
// parts' projected rectangles, shading with blue spill, anti-aliased edges and motion blur.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "sim/frame_code.h"
#include "studio_impl.h"

namespace studio::sim::detail {
namespace {

constexpr uint8_t kNoPart = 255;

// A part in the camera frame with the per-ray constant terms precomputed (ray origin = 0).
struct CamPart {
  bool capsule = true;
  // Capsule: ends a, b; unit axis e; length len; radius r.
  Eigen::Vector3d a, b, e;
  double len = 0, r = 0, r2 = 0;
  Eigen::Vector3d op;  // (-a) without its component along e
  double oe = 0, op2_r2 = 0, a2_r2 = 0, b2_r2 = 0;
  // Ellipsoid: M = diag(1/radii) axes^T, o2 = M (0 - centre).
  Eigen::Matrix3d M;
  Eigen::Vector3d c, o2;
  double o2c = 0;
  double bound = 0;  // capsule: r; ellipsoid: its largest radius (bounding sphere)
  Rect rect;
  std::array<float, 3> albedo{};
  bool coded = false;  // wears the frame code (sim/frame_code.h): the torso
  bool patterned = false;  // StudioOptions::patterned_costume, a clothing part
  Eigen::Vector3d u_ref, w_ref;  // capsule: a world-fixed frame round its axis (camera frame)

  // The costume's pattern at surface point p (camera frame), in [0.6, 1]: on a capsule, of the
  // distance along its axis and the angle round it; on an ellipsoid, of the point on its unit
  // sphere. Both in the part's own coordinates, so every camera sees the same pattern.
  float pattern(const Eigen::Vector3d& p) const {
    double v;
    if (capsule) {
      const Eigen::Vector3d q = p - a;
      const double h = q.dot(e), th = std::atan2(q.dot(w_ref), q.dot(u_ref));
      v = 0.8 + 0.12 * std::sin(2 * M_PI * h / 0.05) * std::cos(3 * th) +
          0.08 * std::sin(2 * M_PI * h / 0.017 + 2 * th);
    } else {
      const Eigen::Vector3d q = M * (p - c);
      v = 0.8 + 0.12 * std::sin(9 * q.x()) * std::sin(9 * q.y() + 1) +
          0.08 * std::sin(23 * q.z() + 7 * q.x());
    }
    return static_cast<float>(v);
  }

  // Ray parameter of the first hit of t * d (t > 0), or +inf.
  double hit(const Eigen::Vector3d& d) const {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (!capsule) {
      const Eigen::Vector3d d2 = M * d;
      const double A = d2.squaredNorm(), B = o2.dot(d2);
      const double disc = B * B - A * o2c;
      if (disc < 0) return kInf;
      const double t = (-B - std::sqrt(disc)) / A;
      return t > 0 ? t : kInf;
    }
    const double dd = d.squaredNorm(), de = d.dot(e);
    const double A = dd - de * de, B = op.dot(d);
    const double disc = B * B - A * op2_r2;
    if (disc < 0) return kInf;
    double axial = -1;
    if (A > 1e-14 * dd) {
      const double t = (-B - std::sqrt(disc)) / A;
      axial = oe + t * de;
      if (axial >= 0 && axial <= len) return t > 0 ? t : kInf;
    } else {
      axial = de > 0 ? -1 : len + 1;  // parallel to the axis: enters through the near cap
    }
    const double B2 = axial < 0 ? -a.dot(d) : -b.dot(d);
    const double C2 = axial < 0 ? a2_r2 : b2_r2;
    const double disc2 = B2 * B2 - dd * C2;
    if (disc2 < 0) return kInf;
    const double t = (-B2 - std::sqrt(disc2)) / dd;
    return t > 0 ? t : kInf;
  }
  // True only if no ray within angle `theta` (radians) of direction d0 can hit the part, so
  // that skipping it changes no hit(). Every point p of the part's core (the segment a-b; the
  // ellipsoid's centre) is within `bound` of any point of the solid; turning the line of d0 by
  // theta moves its distance to p by at most |p| theta (sin is 1-Lipschitz), and a hit needs
  // that distance to reach `bound`. The line (both directions) is a superset of the ray, and
  // the test keeps a 0.1 % + 1 um margin over rounding.
  bool cone_misses(const Eigen::Vector3d& d0, double theta) const {
    const Eigen::Vector3d u = d0.normalized();
    double dist2, reach;
    if (capsule) {
      const Eigen::Vector3d ab = b - a;
      const double au = a.dot(u), eu = ab.dot(u);
      const double A = ab.squaredNorm() - eu * eu, B = a.dot(ab) - au * eu;
      const double C = a.squaredNorm() - au * au;
      dist2 = std::min(C, C + 2 * B + A);  // squared distance at the ends
      if (A > 0) {
        const double t = std::clamp(-B / A, 0.0, 1.0);
        dist2 = std::min(dist2, C + t * (2 * B + t * A));
      }
      reach = bound + std::max(a.norm(), b.norm()) * theta;
    } else {
      const double cu = c.dot(u);
      dist2 = c.squaredNorm() - cu * cu;
      reach = bound + (c.norm() + bound) * theta;
    }
    const double margin = reach * 1.001 + 1e-6;
    return dist2 > margin * margin;
  }
  Eigen::Vector3d normal(const Eigen::Vector3d& p) const {
    if (capsule) {
      const double h = std::clamp((p - a).dot(e), 0.0, len);
      return (p - a - h * e) / r;
    }
    return (M.transpose() * (M * (p - c))).normalized();
  }
};

bool clothing(PartId id) {
  return id != PartId::head && id != PartId::neck && id != PartId::hair && id != PartId::hand_l &&
         id != PartId::hand_r;
}

std::vector<CamPart> to_camera(const CameraCache& cam, const ActorBody& body, int margin,
                               bool frame_code = false, bool patterned = false) {
  std::vector<CamPart> out;
  out.reserve(body.parts.size());
  for (const Part& p : body.parts) {
    CamPart c;
    c.capsule = p.shape == PartShape::capsule;
    Eigen::Vector3d lo, hi;
    if (c.capsule) {
      c.a = cam.R * p.a + cam.t;
      c.b = cam.R * p.b + cam.t;
      c.len = (c.b - c.a).norm();
      c.e = c.len > 0 ? Eigen::Vector3d((c.b - c.a) / c.len) : Eigen::Vector3d::UnitY();
      c.r = p.radius;
      c.r2 = p.radius * p.radius;
      c.oe = -c.a.dot(c.e);
      c.op = -c.a - c.oe * c.e;
      c.op2_r2 = c.op.squaredNorm() - c.r2;
      c.a2_r2 = c.a.squaredNorm() - c.r2;
      c.b2_r2 = c.b.squaredNorm() - c.r2;
      c.bound = c.r;
      if (patterned && clothing(p.id)) {  // a world-fixed direction across the axis, camera frame
        const Eigen::Vector3d axis_w = cam.R.transpose() * c.e;
        Eigen::Vector3d ref = std::abs(axis_w.x()) < 0.9 ? Eigen::Vector3d::UnitX()
                                                         : Eigen::Vector3d::UnitZ();
        ref = (ref - ref.dot(axis_w) * axis_w).normalized();
        c.u_ref = cam.R * ref;
        c.w_ref = c.e.cross(c.u_ref);
      }
      lo = c.a.cwiseMin(c.b).array() - c.r;
      hi = c.a.cwiseMax(c.b).array() + c.r;
    } else {
      const Eigen::Matrix3d axes = cam.R * p.axes;
      c.c = cam.R * p.centre + cam.t;
      c.M = p.radii.cwiseInverse().asDiagonal() * axes.transpose();
      c.o2 = -(c.M * c.c);
      c.o2c = c.o2.squaredNorm() - 1.0;
      c.bound = p.radii.maxCoeff();
      const Eigen::Vector3d half = (axes * p.radii.asDiagonal()).rowwise().norm();
      lo = c.c - half;
      hi = c.c + half;
    }
    Eigen::Vector3d corners[8];
    for (int k = 0; k < 8; ++k) {
      corners[k] = Eigen::Vector3d(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(),
                                   k & 4 ? hi.z() : lo.z());
    }
    c.rect = cam.project_hull(corners, 8, margin);
    c.albedo = {p.albedo.r, p.albedo.g, p.albedo.b};
    c.coded = frame_code && p.id == PartId::torso;
    c.patterned = patterned && clothing(p.id);
    out.push_back(c);
  }
  return out;
}

// Display transfer (gamma 1/2.2) of linear [0, 1] → [0, 255] as a table.
struct Gamma {
  std::array<float, 1025> lut;
  Gamma() {
    for (int i = 0; i <= 1024; ++i) lut[i] = 255.0f * std::pow(i / 1024.0f, 1 / 2.2f);
  }
  float operator()(float x) const { return lut[std::clamp(static_cast<int>(x * 1024.0f), 0, 1024)]; }
};
const Gamma kGamma;

struct Shader {
  Eigen::Vector3d key, fill;  // camera frame
  double spill, ring;
  double exposure = 1;  // relative exposure (sim/projector_light.h)
  std::array<float, 3> response{1, 1, 1};  // the camera's linear gains (StudioOptions)
  std::array<std::array<float, 3>, frame_code::kBands> code{};  // albedo of each band
  // Display colour of the hit on `part` along d at t, given the background colour behind it.
  std::array<float, 3> operator()(const CamPart& part, const Eigen::Vector3d& d, double t,
                                  const Rgb8& bg) const {
    const Eigen::Vector3d p = t * d;
    const Eigen::Vector3d n = part.normal(p);
    const Eigen::Vector3d v = -d.normalized();
    const double ndv = std::max(0.0, n.dot(v));
    const float light = static_cast<float>(0.28 + 0.8 * std::max(0.0, n.dot(key)) +
                                           0.25 * std::max(0.0, n.dot(fill)));
    const float ring_w = static_cast<float>(ring * ndv);
    constexpr float kRing[3] = {0.25f, 0.45f, 1.0f};
    const float s = static_cast<float>(spill * (1 - ndv) * (1 - ndv));
    const float back[3] = {float(bg.r), float(bg.g), float(bg.b)};
    const std::array<float, 3>* albedo = &part.albedo;
    bool banded = false;
    if (part.coded)
      if (const int b = frame_code::band_of((part.M * (p - part.c)).y()); b >= 0) {
        albedo = &code[b];
        banded = true;
      }
    const float pattern = part.patterned && !banded ? part.pattern(p) : 1.0f;
    std::array<float, 3> out;
    for (int k = 0; k < 3; ++k) {
      const float lin = static_cast<float>(exposure) * response[std::size_t(k)] * pattern *
                        (*albedo)[k] * (light + ring_w * kRing[k]);
      out[k] = kGamma(lin) * (1 - s) + back[k] * s;
    }
    return out;
  }
};

Rgb8 to_rgb(const std::array<float, 3>& c) {
  auto q = [](float x) { return static_cast<uint8_t>(std::clamp(x + 0.5f, 0.0f, 255.0f)); };
  return {q(c[0]), q(c[1]), q(c[2])};
}

// Scratch buffers of one thread, reused between frames.
struct Scratch {
  std::vector<float> depth;
  std::vector<uint8_t> id;
  std::vector<Rgb8> bg;
  std::vector<std::array<float, 3>> accum;
  std::vector<uint8_t> hits, edge;  // motion blur: instants covering a pixel; silhouette nearby
};
thread_local Scratch scratch;

// Pinhole cameras: the pixels [x0, x1) of row y (within the part's rectangle) whose centre ray
// may hit `part`; hit() is +inf on every other pixel of the row, so casting only these gives the
// same depth and id. The rays of row y span the plane p.y = Y p.z (Y = (y - cy) / fy); a point of
// the part in it lies within `r` of a core point c (capsule: its axis; ellipsoid: its centre,
// r its largest radius) at distance <= r from that plane, i.e. on the core's piece [t0, t1]
// clipped to that slab. Its X = p.x / p.z lies within the box relaxation of the ball around c,
// between (c.x - r) / (c.z -+ r) and (c.x + r) / (c.z -+ r), each a linear-fractional function
// along the piece and so extreme at its ends (with c.z > r along it; else the whole row). Pixel
// x = fx X + cx + skew Y; one pixel of slack each side for rounding.
std::pair<int, int> row_span(const CameraCache& cam, const CamPart& part, int y) {
  const int rx0 = part.rect.x0, rx1 = part.rect.x1;
  const auto& k = cam.camera.intrinsics;
  const double Y = (y - k.cy) / k.fy;
  const double inv_n = 1 / std::sqrt(1 + Y * Y);
  Eigen::Vector3d a, b;
  double r;
  if (part.capsule) {
    a = part.a, b = part.b, r = part.r;
  } else {
    a = b = part.c, r = part.bound;
  }
  // Signed distances to the row's plane, normal (0, 1, -Y) / |.|.
  const double sa = (a.y() - Y * a.z()) * inv_n, sb = (b.y() - Y * b.z()) * inv_n;
  double t0 = 0, t1 = 1;
  if (sa == sb) {
    if (std::abs(sa) > r) return {rx0, rx0};
  } else {
    const double ta = (-r - sa) / (sb - sa), tb = (r - sa) / (sb - sa);
    t0 = std::max(0.0, std::min(ta, tb));
    t1 = std::min(1.0, std::max(ta, tb));
    if (t0 > t1) return {rx0, rx0};  // the part does not reach the row's plane
  }
  const Eigen::Vector3d c0 = a + t0 * (b - a), c1 = a + t1 * (b - a);
  if (!(c0.z() > r * 1.001 + 1e-6) || !(c1.z() > r * 1.001 + 1e-6)) return {rx0, rx1};
  double lo = INFINITY, hi = -INFINITY;
  for (const Eigen::Vector3d& c : {c0, c1}) {
    for (const double z : {c.z() - r, c.z() + r}) {
      lo = std::min(lo, (c.x() - r) / z);
      hi = std::max(hi, (c.x() + r) / z);
    }
  }
  const double base = k.cx + k.skew * Y;
  const double x0 = std::floor(k.fx * lo + base) - 1, x1 = std::ceil(k.fx * hi + base) + 2;
  if (!(x0 < x1)) return {rx0, rx0};
  const int from = int(std::clamp<double>(x0, rx0, rx1)), to = int(std::clamp<double>(x1, rx0, rx1));
  return {from, std::max(from, to)};
}

// Nearest part per pixel of rect U: depth (ray parameter) and id (kNoPart for none). `cull`
// (pinhole cameras): each part's rows only over row_span().
void cast(const CameraCache& cam, const std::vector<CamPart>& parts, const Rect& U,
          std::vector<float>* depth, std::vector<uint8_t>* id, bool cull = false) {
  const int w = U.x1 - U.x0;
  const std::size_t n = static_cast<std::size_t>(w) * (U.y1 - U.y0);
  depth->assign(n, std::numeric_limits<float>::infinity());
  id->assign(n, kNoPart);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const CamPart& part = parts[k];
    const int y0 = std::max(part.rect.y0, U.y0), y1 = std::min(part.rect.y1, U.y1);
    for (int y = y0; y < y1; ++y) {
      int x0 = part.rect.x0, x1 = part.rect.x1;
      if (cull) std::tie(x0, x1) = row_span(cam, part, y);
      x0 = std::max(x0, U.x0), x1 = std::min(x1, U.x1);
      float* drow = depth->data() + static_cast<std::size_t>(y - U.y0) * w - U.x0;
      uint8_t* irow = id->data() + static_cast<std::size_t>(y - U.y0) * w - U.x0;
      for (int x = x0; x < x1; ++x) {
        const double t = part.hit(cam.ray(x, y));
        if (t < drow[x]) {
          drow[x] = static_cast<float>(t);
          irow[x] = static_cast<uint8_t>(k);
        }
      }
    }
  }
}

// Ray of a sub-pixel position (anti-aliasing).
Eigen::Vector3d sub_ray(const CameraCache& cam, double u, double v) {
  const auto& k = cam.camera.intrinsics;
  const double y = (v - k.cy) / k.fy;
  const Eigen::Vector2d observed((u - k.cx - k.skew * y) / k.fx, y);
  if (cam.pinhole) return {observed.x(), observed.y(), 1.0};
  const Eigen::Vector2d ideal = undistort(cam.camera.distortion, observed);
  return {ideal.x(), ideal.y(), 1.0};
}

Rect union_rect(const std::vector<CamPart>& parts) {
  Rect u;
  for (const CamPart& p : parts) u = u.united(p.rect);
  return u;
}

// Sub-pixel sample offsets (from the pixel centre, in [-0.5, 0.5)) spread over the pixel's area:
// a Hammersley set. For a power-of-two count n it is an n-rooks pattern (every row and every
// column of the n x n sub-grid holds one sample) stratified in every elementary interval, so a
// straight edge's position is resolved to ~1/n px whatever its direction; a regular sqrt(n) grid
// resolves axis-aligned edges, the commonest on a standing actor, only to 1/sqrt(n) px.
std::vector<std::array<double, 2>> pixel_samples(int n) {
  std::vector<std::array<double, 2>> out;
  for (int k = 0; k < n; ++k) {
    double radical = 0, f = 0.5;  // base-2 radical inverse of k (van der Corput)
    for (unsigned i = static_cast<unsigned>(k); i != 0; i >>= 1, f *= 0.5) {
      if (i & 1) radical += f;
    }
    out.push_back({(k + 0.5) / n - 0.5, radical + 0.5 / n - 0.5});
  }
  return out;
}

// The pixel sample each motion-blur instant uses: a fixed shuffle (mt19937, seed 1, whose output
// the standard defines), so that sub-pixel position and time are not correlated.
std::vector<int> instant_sample_order(int n) {
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) order[static_cast<std::size_t>(k)] = k;
  std::mt19937 rng(1);
  for (int k = n - 1; k > 0; --k) {
    std::swap(order[static_cast<std::size_t>(k)],
              order[static_cast<std::size_t>(rng() % static_cast<unsigned>(k + 1))]);
  }
  return order;
}

// The nearest part a sub-pixel ray hits (part -1: none) and where.
struct SubHit {
  int part = -1;
  Eigen::Vector3d d;
  double t = 0;
};

// The hit test of a sub-pixel sample, among the candidate parts `cand` (ascending indices)
// only: the same nearest part (ties go to the lower index either way) when the parts left out
// cannot be hit (cone_misses). cand == nullptr: every part whose rectangle holds pixel (x, y).
SubHit sub_hit(const CameraCache& cam, const std::vector<CamPart>& parts, const uint8_t* cand,
               int n_cand, int x, int y, const std::array<double, 2>& o) {
  SubHit h;
  h.d = sub_ray(cam, x + o[0], y + o[1]);
  double best = std::numeric_limits<double>::infinity();
  auto test = [&](std::size_t k) {
    const double t = parts[k].hit(h.d);
    if (t < best) {
      best = t;
      h.part = static_cast<int>(k);
    }
  };
  if (cand) {
    for (int j = 0; j < n_cand; ++j) test(cand[j]);
  } else {
    for (std::size_t k = 0; k < parts.size(); ++k)
      if (parts[k].rect.contains(x, y)) test(k);
  }
  h.t = best;
  return h;
}

// Colour of one sub-pixel sample at (x + o[0], y + o[1]): the nearest of `parts` whose rectangle
// holds pixel (x, y) (rectangles carry a 1 px margin), or the background colour behind it.
// Counts the sample in *hits when it is on the actor.
std::array<float, 3> sub_sample(const CameraCache& cam, const Shader& shader,
                                const std::vector<CamPart>& parts, int x, int y,
                                const std::array<double, 2>& o, const Rgb8& bg, int* hits) {
  const SubHit h = sub_hit(cam, parts, nullptr, 0, x, y, o);
  if (h.part < 0) return {float(bg.r), float(bg.g), float(bg.b)};
  ++*hits;
  return shader(parts[static_cast<std::size_t>(h.part)], h.d, h.t, bg);
}

// Area-integrated colour of an edge pixel from its sub-samples' hits `h` (offsets `o`): each
// sub-sample that misses takes the background; the sub-samples on one part are shaded once, at
// the one nearest to their centroid, weighted by their count. Coverage — which part, or none,
// each sub-sample sees — is exact; the shading varies little across one pixel (a sub-sample's
// own shading would cost as many shader calls as sub-samples, most of the anti-aliasing's time).
// Counts the hits in *hits.
// every_sample: each sub-sample shaded (StudioOptions::aa_shade_every_sample).
std::array<float, 3> edge_colour(const Shader& shader, const std::vector<CamPart>& parts,
                                 const SubHit* h, const std::vector<std::array<double, 2>>& o,
                                 const Rgb8& bg, bool every_sample, int* hits) {
  const int n = static_cast<int>(o.size());
  int misses = 0;
  for (int k = 0; k < n; ++k) misses += h[k].part < 0;
  *hits += n - misses;
  std::array<float, 3> sum{float(bg.r) * misses, float(bg.g) * misses, float(bg.b) * misses};
  if (every_sample) {
    for (int k = 0; k < n; ++k) {
      if (h[k].part < 0) continue;
      const auto c = shader(parts[static_cast<std::size_t>(h[k].part)], h[k].d, h[k].t, bg);
      for (int i = 0; i < 3; ++i) sum[i] += c[i];
    }
    return sum;
  }
  uint64_t done = 0;  // sub-samples already accounted for (n <= 64)
  for (int k = 0; k < n; ++k) {
    if (h[k].part < 0 || (done >> k & 1)) continue;
    const int part = h[k].part;
    double cx = 0, cy = 0;
    int count = 0;
    for (int j = k; j < n; ++j)
      if (h[j].part == part) {
        cx += o[j][0];
        cy += o[j][1];
        ++count;
      }
    cx /= count;
    cy /= count;
    int rep = k;
    double rep_d2 = std::numeric_limits<double>::infinity();
    for (int j = k; j < n; ++j)
      if (h[j].part == part) {
        done |= uint64_t{1} << j;
        const double d2 = (o[j][0] - cx) * (o[j][0] - cx) + (o[j][1] - cy) * (o[j][1] - cy);
        if (d2 < rep_d2) {
          rep_d2 = d2;
          rep = j;
        }
      }
    const auto c = shader(parts[static_cast<std::size_t>(part)], h[rep].d, h[rep].t, bg);
    for (int i = 0; i < 3; ++i) sum[i] += c[i] * count;
  }
  return sum;
}

// Angle (radians) that bounds, for a pinhole camera, the angle between the ray through a pixel's
// centre and any ray through the pixel's area (offsets within +-0.5 px): |d0| >= 1 (z = 1), and
// the normalised offset is at most (0.5 + 0.5 |skew| / fy) / fx across, 0.5 / fy down.
double pixel_cone(const CameraCache& cam) {
  const auto& k = cam.camera.intrinsics;
  const double dx = (0.5 + 0.5 * std::abs(k.skew) / k.fy) / k.fx, dy = 0.5 / k.fy;
  const double s = std::hypot(dx, dy);
  return s < 0.5 ? 1.01 * std::asin(s) : -1;  // -1: too wide to bound, no culling
}

// Coverage fraction k / n as a matte value in 0..255.
uint8_t matte_value(int k, int n) { return static_cast<uint8_t>((255 * k + n / 2) / n); }

}  // namespace

Rect touched_rect(const StudioOptions& options, const CameraCache& cam,
                  const PreparedFrame& frame) {
  Rect U = union_rect(to_camera(cam, frame.truth.body, 1));
  for (const ActorBody& b : frame.blur_bodies) U = U.united(union_rect(to_camera(cam, b, 1)));
  if (!U.empty()) {
    U = {std::max(0, U.x0 - 1), std::max(0, U.y0 - 1), std::min(cam.camera.width, U.x1 + 1),
         std::min(cam.camera.height, U.y1 + 1)};
  }
  return U.united(shadow_rect(cam, frame.shadow));
}

void render_actor(const StudioOptions& options, const CameraCache& cam, const PreparedFrame& frame,
                  Image<Rgb8>* image, Mask* mask, Image<uint8_t>* matte) {
  const bool cull = !options.reference_renderer && cam.pinhole;
  apply_shadow(cam, frame.shadow, image, cull);
  const int width = cam.camera.width, height = cam.camera.height;
  const std::vector<CamPart> parts =
      to_camera(cam, frame.truth.body, 1, options.frame_code, options.patterned_costume);
  // (touched_rect below repeats this rectangle arithmetic: keep the two in step.)
  Shader shader{cam.R * kKeyLight,
                cam.R * kFillLight,
                options.spill,
                options.ring_light * options.projector_light.ring_level,
                options.projector_light.exposure,
                cam.response};
  for (int b = 0; b < frame_code::kBands; ++b) {
    const Albedo a = frame_code::albedo(frame_code::digit(frame.truth.frame, b));
    shader.code[b] = {a.r, a.g, a.b};
  }
  Rect U = union_rect(parts);
  std::vector<std::vector<CamPart>> blur;
  for (const ActorBody& b : frame.blur_bodies) {
    blur.push_back(to_camera(cam, b, 1, options.frame_code, options.patterned_costume));
    U = U.united(union_rect(blur.back()));
  }
  if (U.empty()) return;
  // Grow by one pixel (anti-aliasing looks at neighbours), clipped to the image.
  U = {std::max(0, U.x0 - 1), std::max(0, U.y0 - 1), std::min(width, U.x1 + 1),
       std::min(height, U.y1 + 1)};
  const int w = U.x1 - U.x0;
  const std::size_t n = static_cast<std::size_t>(w) * (U.y1 - U.y0);
  auto at = [&](int x, int y) { return static_cast<std::size_t>(y - U.y0) * w + (x - U.x0); };
  Scratch& s = scratch;
  // Background behind the actor (after shadow) for spill, anti-aliasing and blur.
  s.bg.resize(n);
  for (int y = U.y0; y < U.y1; ++y) std::copy_n(&(*image)(U.x0, y), w, s.bg.data() + at(U.x0, y));
  cast(cam, parts, U, &s.depth, &s.id, cull);
  for (int y = U.y0; y < U.y1; ++y) {
    uint8_t* mrow = &(*mask)(0, y);
    Rgb8* irow = &(*image)(0, y);
    for (int x = U.x0; x < U.x1; ++x) {
      const std::size_t i = at(x, y);
      if (s.id[i] == kNoPart) continue;
      mrow[x] = 255;
      if (matte) (*matte)(x, y) = 255;
      if (blur.empty()) irow[x] = to_rgb(shader(parts[s.id[i]], cam.ray(x, y), s.depth[i], s.bg[i]));
    }
  }
  if (!blur.empty()) {
    // Motion blur: average the actor over the shutter's instants, at pixel centres; pixels the
    // silhouette crosses at some instant are then integrated over space and time (below).
    s.accum.assign(n, {0, 0, 0});
    s.hits.assign(n, 0);
    s.edge.assign(n, 0);
    for (const auto& sub : blur) {
      cast(cam, sub, U, &s.depth, &s.id);
      for (int y = U.y0; y < U.y1; ++y) {
        for (int x = U.x0; x < U.x1; ++x) {
          const std::size_t i = at(x, y);
          const bool covered = s.id[i] != kNoPart;
          s.hits[i] += covered;
          if (x + 1 < U.x1 && covered != (s.id[i + 1] != kNoPart)) s.edge[i] = s.edge[i + 1] = 1;
          if (y + 1 < U.y1 && covered != (s.id[i + w] != kNoPart)) s.edge[i] = s.edge[i + w] = 1;
          const Rgb8& b = s.bg[i];
          const auto c = covered ? shader(sub[s.id[i]], cam.ray(x, y), s.depth[i], b)
                                 : std::array<float, 3>{float(b.r), float(b.g), float(b.b)};
          for (int k = 0; k < 3; ++k) s.accum[i][k] += c[k];
        }
      }
    }
    const int instants = static_cast<int>(blur.size());
    const float inv = 1.0f / static_cast<float>(instants);
    const auto samples = pixel_samples(instants);
    const auto order = instant_sample_order(instants);
    for (int y = U.y0; y < U.y1; ++y) {
      for (int x = U.x0; x < U.x1; ++x) {
        const std::size_t i = at(x, y);
        std::array<float, 3> a = s.accum[i];
        int hits = s.hits[i];
        const bool crossed = s.edge[i] || (hits != 0 && hits != instants);
        if (options.antialias && crossed) {
          // Space-time integration: instant k seen through its own sub-pixel sample.
          a = {0, 0, 0};
          hits = 0;
          for (int k = 0; k < instants; ++k) {
            const auto c = sub_sample(cam, shader, blur[static_cast<std::size_t>(k)], x, y,
                                      samples[static_cast<std::size_t>(order[k])], s.bg[i], &hits);
            for (int j = 0; j < 3; ++j) a[j] += c[j];
          }
        }
        (*image)(x, y) = to_rgb({a[0] * inv, a[1] * inv, a[2] * inv});
        if (matte) (*matte)(x, y) = matte_value(hits, instants);
      }
    }
    return;
  }
  if (!options.antialias) return;
  // Anti-aliasing: pixels on either side of the silhouette integrate aa_samples sub-samples over
  // their area (mask unchanged).
  const auto samples = pixel_samples(options.aa_samples);
  const float inv = 1.0f / static_cast<float>(samples.size());
  const double cone = cull ? pixel_cone(cam) : -1;
  std::vector<uint8_t> cand(parts.size());
  std::vector<SubHit> sub_hits(samples.size());
  for (int y = U.y0; y < U.y1; ++y) {
    const uint8_t* m = &(*mask)(0, y);
    const uint8_t* up = y > 0 ? &(*mask)(0, y - 1) : m;
    const uint8_t* down = y + 1 < height ? &(*mask)(0, y + 1) : m;
    for (int x = U.x0; x < U.x1; ++x) {
#if defined(__SSE2__)
      // 16 pixels at a time away from the image's sides: skip a block with no edge pixel.
      if (x > 0 && x + 17 <= width && x + 16 <= U.x1) {
        const auto load = [](const uint8_t* p) {
          return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
        };
        const __m128i c = load(m + x);
        const __m128i diff =
            _mm_or_si128(_mm_or_si128(_mm_xor_si128(c, load(m + x - 1)),
                                      _mm_xor_si128(c, load(m + x + 1))),
                         _mm_or_si128(_mm_xor_si128(c, load(up + x)), _mm_xor_si128(c, load(down + x))));
        if (_mm_movemask_epi8(_mm_cmpeq_epi8(diff, _mm_setzero_si128())) == 0xFFFF) {
          x += 15;
          continue;
        }
      }
#endif
      const uint8_t c = m[x];
      const bool edge = (x > 0 && m[x - 1] != c) || (x + 1 < width && m[x + 1] != c) ||
                        up[x] != c || down[x] != c;
      if (!edge) continue;
      int hits = 0;
      const bool culled = cone > 0;
      int n_cand = 0;
      if (culled) {
        // The parts some sub-sample may hit: rectangle holds the pixel, the cone cannot miss.
        const Eigen::Vector3d d0 = cam.ray(x, y);
        for (std::size_t k = 0; k < parts.size(); ++k) {
          if (parts[k].rect.contains(x, y) && !parts[k].cone_misses(d0, cone)) {
            cand[static_cast<std::size_t>(n_cand++)] = static_cast<uint8_t>(k);
          }
        }
        // No part within reach: every sub-sample sees the background, which the pixel already
        // shows (the mean of identical samples is the sample itself; matte 0).
        if (n_cand == 0) {
          if (matte) (*matte)(x, y) = 0;
          continue;
        }
      }
      for (std::size_t k = 0; k < samples.size(); ++k)
        sub_hits[k] = sub_hit(cam, parts, culled ? cand.data() : nullptr, n_cand, x, y, samples[k]);
      const auto sum = edge_colour(shader, parts, sub_hits.data(), samples, s.bg[at(x, y)],
                                   options.aa_shade_every_sample, &hits);
      (*image)(x, y) = to_rgb({sum[0] * inv, sum[1] * inv, sum[2] * inv});
      if (matte) (*matte)(x, y) = matte_value(hits, static_cast<int>(samples.size()));
    }
  }
}

}  // namespace studio::sim::detail

#include "testing/truth.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "keyer/keyer.h"
#include "testing/point_index.h"
#include "testing/raster.h"

namespace studio::offline::testing {
namespace {

std::vector<Eigen::Vector3d> mesh_samples(const hull::Mesh& mesh, int n) {
  std::vector<double> cum;
  double total = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cum.push_back(total);
  }
  std::vector<Eigen::Vector3d> out;
  if (cum.empty()) return out;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < n; ++k) {
    const std::size_t f = std::min(
        cum.size() - 1,
        std::size_t(std::lower_bound(cum.begin(), cum.end(), u(rng) * total) - cum.begin()));
    const auto& t = mesh.triangles[f];
    double r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    out.push_back(mesh.vertices[t[0]].cast<double>() +
                  r1 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cast<double>() +
                  r2 * (mesh.vertices[t[2]] - mesh.vertices[t[0]]).cast<double>());
  }
  return out;
}

Distances stats(std::vector<double> d) {
  Distances s;
  if (d.empty()) return s;
  double sum = 0;
  for (double x : d) sum += x;
  s.mean = sum / double(d.size());
  const std::size_t k = std::min(d.size() - 1, std::size_t(0.95 * double(d.size())));
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(k), d.end());
  s.p95 = d[k];
  return s;
}

}  // namespace

SurfaceScore surface_distance(const hull::Mesh& mesh, const sim::ActorBody& truth, int samples) {
  const std::vector<Eigen::Vector3d> on_truth = truth.surface_samples(samples, 3);
  const std::vector<Eigen::Vector3d> on_mesh = mesh_samples(mesh, samples);
  const PointIndex truth_index(on_truth, 0.01), mesh_index(on_mesh, 0.01);
  std::vector<double> acc, comp;
  for (const auto& x : on_mesh) acc.push_back(truth_index.nearest(x));
  for (const auto& x : on_truth) comp.push_back(mesh_index.nearest(x));
  SurfaceScore s;
  s.accuracy = stats(acc);
  s.completeness = stats(comp);
  std::vector<double> both = acc;
  both.insert(both.end(), comp.begin(), comp.end());
  s.both = stats(std::move(both));
  return s;
}

namespace {

// Approximate distance of x to a part's surface (exact for capsules; ellipsoids: the radial
// excess scaled by the smallest radius).
double part_distance(const sim::Part& p, const Eigen::Vector3d& x) {
  if (p.shape == sim::PartShape::capsule) {
    const Eigen::Vector3d ab = p.b - p.a;
    const double len2 = ab.squaredNorm();
    const double h = len2 > 0 ? std::clamp((x - p.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return std::abs((x - p.a - h * ab).norm() - p.radius);
  }
  const Eigen::Vector3d u = (p.axes.transpose() * (x - p.centre)).cwiseQuotient(p.radii);
  return std::abs(u.norm() - 1) * p.radii.minCoeff();
}

int region_of(const sim::ActorBody& body, const Eigen::Vector3d& x) {
  int best = 0;
  double best_d = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < body.parts.size(); ++k) {
    const double d = part_distance(body.parts[k], x);
    if (d < best_d) best_d = d, best = int(k);
  }
  using P = sim::PartId;
  switch (P(best)) {
    case P::pelvis:
    case P::torso:
    case P::shoulders:
      return 0;
    case P::upper_arm_l:
    case P::lower_arm_l:
    case P::hand_l:
    case P::upper_arm_r:
    case P::lower_arm_r:
    case P::hand_r:
      return 1;
    case P::neck:
    case P::head:
    case P::hair:
      return 3;
    default:
      return 2;
  }
}

}  // namespace

std::vector<ErrorBucket> error_breakdown(const hull::Mesh& mesh, const sim::ActorBody& truth,
                                         double cell, int samples) {
  const std::vector<Eigen::Vector3d> on_truth = truth.surface_samples(samples, 3);
  const std::vector<Eigen::Vector3d> on_mesh = mesh_samples(mesh, samples);
  const PointIndex truth_index(on_truth, 0.01), mesh_index(on_mesh, 0.01);
  struct S {
    double d;
    int region;
  };
  std::vector<S> all;
  for (const auto& x : on_mesh) {
    // The region of the nearest body part (the sample itself may be off the body).
    all.push_back({truth_index.nearest(x), region_of(truth, x)});
  }
  for (const auto& x : on_truth) all.push_back({mesh_index.nearest(x), region_of(truth, x)});
  std::vector<double> ds;
  double total = 0;
  for (const S& s : all) ds.push_back(s.d), total += s.d;
  const std::size_t k = std::min(ds.size() - 1, std::size_t(0.95 * double(ds.size())));
  std::nth_element(ds.begin(), ds.begin() + std::ptrdiff_t(k), ds.end());
  const double p95 = ds[k];
  static const char* kNames[4] = {"torso", "arms", "legs", "head"};
  std::vector<ErrorBucket> out;
  for (int far = 0; far < 2; ++far)
    for (int r = 0; r < 4; ++r) out.push_back({kNames[r], far == 1});
  double above = 0;
  for (const S& s : all) {
    ErrorBucket& b = out[std::size_t((s.d > cell ? 4 : 0) + s.region)];
    b.samples += 1.0 / double(all.size());
    b.share += s.d / total;
    if (s.d > p95) b.p95_share += 1, above += 1;
  }
  for (ErrorBucket& b : out) b.p95_share = above > 0 ? b.p95_share / above : 0;
  return out;
}

std::vector<double> distances_to_truth(const std::vector<Eigen::Vector3d>& points,
                                       const sim::ActorBody& truth, int samples) {
  const std::vector<Eigen::Vector3d> on_truth = truth.surface_samples(samples, 3);
  const PointIndex index(on_truth, 0.01);
  std::vector<double> out;
  out.reserve(points.size());
  for (const auto& x : points) out.push_back(index.nearest(x));
  return out;
}

std::vector<Eigen::Vector3d> far_mesh_points(const hull::Mesh& mesh, const sim::ActorBody& truth,
                                             double distance, int samples) {
  const std::vector<Eigen::Vector3d> on_truth = truth.surface_samples(samples, 3);
  const PointIndex index(on_truth, 0.01);
  std::vector<Eigen::Vector3d> out;
  for (const auto& x : mesh_samples(mesh, samples)) {
    if (index.nearest(x) > distance) out.push_back(x);
  }
  return out;
}

std::vector<ColourView> Frame::views() const {
  std::vector<ColourView> v;
  for (std::size_t c = 0; c < cameras.size(); ++c)
    v.push_back({&cameras[c], images[c].view(), &masks[c]});
  return v;
}

Frame render_frame(const sim::SimulatedStudio& studio, int64_t frame) {
  Frame f;
  f.cameras = studio.cameras();
  f.truth = studio.render_all(frame, &f.images, nullptr);
  auto keyer = keyer::Keyer::create({}).value();
  f.masks.resize(f.cameras.size());
  for (std::size_t c = 0; c < f.cameras.size(); ++c)
    (void)keyer.key(f.images[c].view(), f.masks[c]);
  return f;
}

namespace {

// Z-buffered, perspective-correct raster of a vertex-coloured mesh; `covered` per pixel.
Image<Rgb8> raster(const hull::Mesh& mesh, const std::vector<Eigen::Vector3f>& colours,
                   const Camera& camera, Rgb8 background, std::vector<uint8_t>* covered) {
  const int W = camera.width, H = camera.height;
  Image<Rgb8> out(W, H);
  covered->assign(std::size_t(W) * H, 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) out.view().row(y)[x] = background;
  raster_fragments(
      mesh, camera,
      [&](int x, int y, const std::array<uint32_t, 3>& t, double w0, double w1, double w2,
          double ws) {
        (*covered)[std::size_t(y) * W + x] = 1;
        const Eigen::Vector3f col =
            (float(w0) * colours[t[0]] + float(w1) * colours[t[1]] + float(w2) * colours[t[2]]) /
            float(ws);
        auto q8 = [](float v) { return uint8_t(std::clamp(v + 0.5f, 0.0f, 255.0f)); };
        out.view().row(y)[x] = Rgb8{q8(col.x()), q8(col.y()), q8(col.z())};
      });
  return out;
}

}  // namespace

Image<Rgb8> render_coloured(const hull::Mesh& mesh, const std::vector<Eigen::Vector3f>& colours,
                            const Camera& camera, Rgb8 background) {
  std::vector<uint8_t> covered;
  return raster(mesh, colours, camera, background, &covered);
}

Image<Rgb8> render_over(const hull::Mesh& mesh, const std::vector<Eigen::Vector3f>& colours,
                        const Camera& camera, const Image<Rgb8>& plate, int ss, Mask* coverage) {
  // The same camera with ss x ss sub-pixels per pixel (pixel centres at integer coordinates:
  // sub-pixel (i, j) of pixel (x, y) is at x + (i + 0.5) / ss - 0.5).
  Camera fine = camera;
  fine.width = camera.width * ss, fine.height = camera.height * ss;
  fine.intrinsics.fx *= ss, fine.intrinsics.fy *= ss, fine.intrinsics.skew *= ss;
  fine.intrinsics.cx = (camera.intrinsics.cx + 0.5) * ss - 0.5;
  fine.intrinsics.cy = (camera.intrinsics.cy + 0.5) * ss - 0.5;
  std::vector<uint8_t> covered;
  const Image<Rgb8> big = raster(mesh, colours, fine, {0, 0, 0}, &covered);
  Image<Rgb8> out(camera.width, camera.height);
  if (coverage) *coverage = Mask(camera.width, camera.height);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Rgb8 bg = plate.view().row(y)[x];
      float sum[3] = {0, 0, 0};
      int hits = 0;
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const int fx = x * ss + i, fy = y * ss + j;
          const bool on = covered[std::size_t(fy) * fine.width + fx] != 0;
          const Rgb8 c = on ? big.view().row(fy)[fx] : bg;
          sum[0] += c.r, sum[1] += c.g, sum[2] += c.b;
          hits += on;
        }
      const float n = float(ss * ss);
      auto q8 = [](float v) { return uint8_t(std::clamp(v + 0.5f, 0.0f, 255.0f)); };
      out.view().row(y)[x] = Rgb8{q8(sum[0] / n), q8(sum[1] / n), q8(sum[2] / n)};
      if (coverage) coverage->view().row(y)[x] = hits ? 255 : 0;
    }
  return out;
}

double psnr(const Image<Rgb8>& image, const Image<Rgb8>& truth, const Mask& region) {
  double se = 0;
  std::size_t n = 0;
  for (int y = 0; y < truth.height(); ++y)
    for (int x = 0; x < truth.width(); ++x) {
      if (!region.view().row(y)[x]) continue;
      const Rgb8 a = image.view().row(y)[x], b = truth.view().row(y)[x];
      se += double(a.r - b.r) * (a.r - b.r) + double(a.g - b.g) * (a.g - b.g) +
            double(a.b - b.b) * (a.b - b.b);
      n += 3;
    }
  if (n == 0) return 0;
  const double mse = se / double(n);
  return mse <= 0 ? 99 : 10 * std::log10(255.0 * 255.0 / mse);
}

Mask erode(const Mask& mask, int r) {
  Mask out(mask.width(), mask.height());
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) {
      bool all = true;
      for (int dy = -r; dy <= r && all; ++dy)
        for (int dx = -r; dx <= r && all; ++dx) {
          const int xx = x + dx, yy = y + dy;
          all = xx >= 0 && yy >= 0 && xx < mask.width() && yy < mask.height() &&
                mask.view().row(yy)[xx] != 0;
        }
      out.view().row(y)[x] = all ? 255 : 0;
    }
  return out;
}

hull::GridSpec studio_grid(int n) {
  hull::GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = hull::Axis::y;
  g.cells_u = g.cells_v = n;
  return g;
}

}  // namespace studio::offline::testing

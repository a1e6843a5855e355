#include "testing/texture_oracle.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "testing/raster.h"
#include "testing/truth.h"

namespace studio::offline::testing {
namespace {

// The same camera with ss x ss sub-pixels per pixel (render_over's convention).
Camera fine_camera(const Camera& camera, int ss) {
  Camera fine = camera;
  fine.width = camera.width * ss, fine.height = camera.height * ss;
  fine.intrinsics.fx *= ss, fine.intrinsics.fy *= ss, fine.intrinsics.skew *= ss;
  fine.intrinsics.cx = (camera.intrinsics.cx + 0.5) * ss - 0.5;
  fine.intrinsics.cy = (camera.intrinsics.cy + 0.5) * ss - 0.5;
  return fine;
}

uint8_t q8(float v) { return uint8_t(std::clamp(v + 0.5f, 0.0f, 255.0f)); }

}  // namespace

hull::Mesh true_mesh(const sim::ActorBody& body, int segments) {
  const sim::TriangleMesh t = body.mesh(segments);
  hull::Mesh m;
  m.vertices = t.vertices;
  m.triangles = t.triangles;
  hull::compute_normals(m);
  return m;
}

std::vector<SurfaceSample> truth_surface(const sim::ActorBody& body, const Camera& camera, int ss) {
  const Camera fine = fine_camera(camera, ss);
  std::vector<SurfaceSample> out(std::size_t(fine.width) * fine.height);
  // Only the projected bounds of the body are cast.
  Eigen::Vector3d lo, hi;
  body.bounds(&lo, &hi);
  double x0 = fine.width, y0 = fine.height, x1 = -1, y1 = -1;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d c((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                            (k & 4) ? hi.z() : lo.z());
    Eigen::Vector2d p;
    if (!fine.project(c, &p)) return out;  // the body straddles the camera: not for this tool
    x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
  }
  const Eigen::Vector3d origin = fine.centre_in_world();
  for (int y = std::max(0, int(y0) - 1); y <= std::min(fine.height - 1, int(y1) + 1); ++y)
    for (int x = std::max(0, int(x0) - 1); x <= std::min(fine.width - 1, int(x1) + 1); ++x) {
      const auto h = body.ray_hit(origin, fine.pixel_ray_in_world(Eigen::Vector2d(x, y)));
      if (!h) continue;
      SurfaceSample& s = out[std::size_t(y) * fine.width + x];
      s.x = h->point, s.n = h->normal, s.hit = true;
    }
  return out;
}

std::vector<SurfaceSample> mesh_surface(const hull::Mesh& mesh, const Camera& camera, int ss) {
  const Camera fine = fine_camera(camera, ss);
  std::vector<SurfaceSample> out(std::size_t(fine.width) * fine.height);
  raster_fragments(mesh, fine,
                   [&](int x, int y, const std::array<uint32_t, 3>& t, double w0, double w1,
                       double w2, double ws) {
                     SurfaceSample& s = out[std::size_t(y) * fine.width + x];
                     s.x = (w0 * mesh.vertices[t[0]].cast<double>() +
                            w1 * mesh.vertices[t[1]].cast<double>() +
                            w2 * mesh.vertices[t[2]].cast<double>()) /
                           ws;
                     const Eigen::Vector3d n = w0 * mesh.normals[t[0]].cast<double>() +
                                               w1 * mesh.normals[t[1]].cast<double>() +
                                               w2 * mesh.normals[t[2]].cast<double>();
                     s.n = n.squaredNorm() > 0 ? n.normalized() : Eigen::Vector3d::Zero();
                     s.hit = true;
                   });
  return out;
}

Image<Rgb8> blend_over(const std::vector<SurfaceSample>& surface, const Camera& camera, int ss,
                       const TextureBlend& blend, const Image<Rgb8>& plate, Mask* coverage,
                       std::size_t* unseen) {
  const int W = camera.width * ss, H = camera.height * ss;
  std::vector<Eigen::Vector3f> colour(surface.size(), Eigen::Vector3f::Zero());
  std::vector<uint8_t> known(surface.size(), 0);
  std::size_t missing = 0;
  for (std::size_t k = 0; k < surface.size(); ++k) {
    if (!surface[k].hit) continue;
    if (surface[k].n.squaredNorm() > 0.5) {
      if (auto c = blend.colour(surface[k].x, surface[k].n)) {
        colour[k] = *c, known[k] = 1;
        continue;
      }
    }
    ++missing;
  }
  if (unseen) *unseen = missing;
  // Fill unseen hits from seen 4-neighbours, ring by ring (Jacobi steps).
  for (bool changed = missing > 0; changed;) {
    changed = false;
    std::vector<std::pair<std::size_t, Eigen::Vector3f>> fill;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t k = std::size_t(y) * W + x;
        if (!surface[k].hit || known[k]) continue;
        Eigen::Vector3f s = Eigen::Vector3f::Zero();
        int count = 0;
        const auto add = [&](int xx, int yy) {
          if (xx < 0 || yy < 0 || xx >= W || yy >= H) return;
          const std::size_t m = std::size_t(yy) * W + xx;
          if (known[m]) s += colour[m], ++count;
        };
        add(x - 1, y), add(x + 1, y), add(x, y - 1), add(x, y + 1);
        if (count) fill.emplace_back(k, s / float(count));
      }
    for (const auto& [k, c] : fill) colour[k] = c, known[k] = 1, changed = true;
  }
  Image<Rgb8> out(camera.width, camera.height);
  if (coverage) *coverage = Mask(camera.width, camera.height);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Rgb8 bg = plate.view().row(y)[x];
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int hits = 0;
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const std::size_t k = std::size_t(y * ss + j) * W + std::size_t(x * ss + i);
          if (surface[k].hit) {
            sum += known[k] ? colour[k] : Eigen::Vector3f(128, 128, 128);
            ++hits;
          } else {
            sum += Eigen::Vector3f(bg.r, bg.g, bg.b);
          }
        }
      sum /= float(ss * ss);
      out.view().row(y)[x] = Rgb8{q8(sum.x()), q8(sum.y()), q8(sum.z())};
      if (coverage) coverage->view().row(y)[x] = hits ? 255 : 0;
    }
  return out;
}

HeldOutScore score_held_out(const Image<Rgb8>& render, const Mask& coverage,
                            const Image<Rgb8>& truth, const Mask& true_mask) {
  const Mask interior = erode(true_mask, 2);
  HeldOutScore s;
  double se[3] = {0, 0, 0};
  std::size_t px[3] = {0, 0, 0};
  for (int y = 0; y < truth.height(); ++y)
    for (int x = 0; x < truth.width(); ++x) {
      const bool in_true = true_mask.view().row(y)[x] != 0;
      const bool covered = coverage.view().row(y)[x] != 0;
      if (!in_true && !covered) continue;
      const int k = interior.view().row(y)[x] ? 0 : in_true ? 1 : 2;
      const Rgb8 a = render.view().row(y)[x], b = truth.view().row(y)[x];
      se[k] += double(a.r - b.r) * (a.r - b.r) + double(a.g - b.g) * (a.g - b.g) +
               double(a.b - b.b) * (a.b - b.b);
      ++px[k];
      s.uncovered_px += k == 0 && !covered;
    }
  const auto db = [](double e, std::size_t n) {
    if (n == 0) return 0.0;
    const double mse = e / double(3 * n);
    return mse <= 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
  };
  s.interior_db = db(se[0], px[0]);
  s.union_db = db(se[0] + se[1] + se[2], px[0] + px[1] + px[2]);
  const double total = std::max(1e-12, se[0] + se[1] + se[2]);
  s.share_interior = se[0] / total, s.share_border = se[1] / total, s.share_outside = se[2] / total;
  s.interior_px = px[0], s.border_px = px[1], s.outside_px = px[2];
  return s;
}

}  // namespace studio::offline::testing

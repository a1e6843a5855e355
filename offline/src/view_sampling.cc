#include "offline/view_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::offline {

Expected<std::vector<SampledView>> prepare_views(std::span<const ColourView> views,
                                                 int edge_margin_px) {
  if (views.empty()) return fail("no camera views");
  std::vector<SampledView> out;
  out.reserve(views.size());
  for (const ColourView& cv : views) {
    const Camera& cam = *cv.camera;
    if (cv.image.width() != cam.width || cv.image.height() != cam.height) {
      return fail("camera " + cam.id + ": image is " + std::to_string(cv.image.width()) + "x" +
                  std::to_string(cv.image.height()) + ", camera is " + std::to_string(cam.width) +
                  "x" + std::to_string(cam.height));
    }
    if (!cv.mask || cv.mask->width() != cam.width || cv.mask->height() != cam.height) {
      return fail("camera " + cam.id + ": mask size differs from the camera's");
    }
    SampledView v;
    v.camera = &cam;
    v.R = cam.cam_from_world.R();
    v.t = cam.cam_from_world.translation;
    v.centre = cam.centre_in_world();
    v.k = cam.intrinsics;
    v.pinhole = cam.distortion.is_identity();
    v.image = cv.image;
    const int W = cam.width, H = cam.height, m = edge_margin_px;
    std::vector<uint8_t> in(std::size_t(W) * H, 0), tmp(std::size_t(W) * H, 0);
    for (int y = 0; y < H; ++y)
      for (const Run& r : cv.mask->row(y))
        std::fill(in.begin() + std::size_t(y) * W + r.begin,
                  in.begin() + std::size_t(y) * W + r.end, 1);
    // Erosion by a (2m+1)^2 square, separable: rows, then columns.
    std::vector<int> left(W);
    for (int y = 0; y < H; ++y) {
      const uint8_t* row = &in[std::size_t(y) * W];
      int run = 0;  // inside pixels ending at x
      for (int x = 0; x < W; ++x) left[x] = run = row[x] ? run + 1 : 0;
      int right = 0;
      for (int x = W - 1; x >= 0; --x) {
        right = row[x] ? right + 1 : 0;
        tmp[std::size_t(y) * W + x] = left[x] > m && right > m;
      }
    }
    // Columns, row by row (memory order): inside pixels ending at (x, y) from above, then from
    // below.
    v.interior.assign(std::size_t(W) * H, 0);
    std::vector<int> above(std::size_t(W) * H), run(W, 0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        above[std::size_t(y) * W + x] = run[x] = tmp[std::size_t(y) * W + x] ? run[x] + 1 : 0;
    std::fill(run.begin(), run.end(), 0);
    for (int y = H - 1; y >= 0; --y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = std::size_t(y) * W + x;
        run[x] = tmp[i] ? run[x] + 1 : 0;
        v.interior[i] = above[i] > m && run[x] > m;
      }
    out.push_back(std::move(v));
  }
  return out;
}

void DepthBuffer::reset(const SampledView& v) {
  constexpr float inf = std::numeric_limits<float>::infinity();
  if (width_ == v.camera->width && height_ == v.camera->height &&
      depth_.size() == std::size_t(width_) * std::size_t(height_)) {
    // Only the rows and columns drawn since the last reset (the carve resets every iteration).
    for (int y = dirty_y0_; y <= dirty_y1_; ++y)
      std::fill_n(&depth_[std::size_t(y) * width_ + dirty_x0_], dirty_x1_ - dirty_x0_ + 1, inf);
  } else {
    width_ = v.camera->width, height_ = v.camera->height;
    depth_.assign(std::size_t(width_) * height_, inf);
  }
  dirty_x0_ = width_, dirty_y0_ = height_, dirty_x1_ = -1, dirty_y1_ = -1;
}

void DepthBuffer::mark(int x0, int y0, int x1, int y1) {
  dirty_x0_ = std::min(dirty_x0_, x0), dirty_y0_ = std::min(dirty_y0_, y0);
  dirty_x1_ = std::max(dirty_x1_, x1), dirty_y1_ = std::max(dirty_y1_, y1);
}

void DepthBuffer::splat(const SampledView& v, const Eigen::Vector3d& x, double size) {
  Eigen::Vector3d xc;
  Eigen::Vector2d p;
  if (!v.project(x, &p, &xc)) return;
  const double r = 0.5 * size * std::max(v.k.fx, v.k.fy) / xc.z();
  const int x0 = std::max(0, int(std::ceil(p.x() - r))),
            x1 = std::min(width_ - 1, int(std::floor(p.x() + r)));
  const int y0 = std::max(0, int(std::ceil(p.y() - r))),
            y1 = std::min(height_ - 1, int(std::floor(p.y() + r)));
  const float z = float(xc.z());
  if (x0 > x1 || y0 > y1) return;
  mark(x0, y0, x1, y1);
  for (int y = y0; y <= y1; ++y) {
    float* row = &depth_[std::size_t(y) * width_];
    for (int xx = x0; xx <= x1; ++xx) row[xx] = std::min(row[xx], z);
  }
}

void DepthBuffer::mesh(const SampledView& v, const hull::Mesh& m) {
  // Each vertex projected once (a vertex is in ~6 triangles).
  const std::size_t nv = m.vertices.size();
  projected_.resize(nv);
  depth_of_.resize(nv);
  for (std::size_t n = 0; n < nv; ++n) {
    Eigen::Vector3d xc;
    depth_of_[n] = v.project(m.vertices[n].cast<double>(), &projected_[n], &xc) ? xc.z() : -1;
  }
  for (const auto& t : m.triangles) {
    Eigen::Vector2d p[3];
    double z[3];
    bool front = true;
    for (int k = 0; k < 3 && front; ++k) {
      p[k] = projected_[t[k]], z[k] = depth_of_[t[k]];
      front = z[k] > 0;
    }
    if (front) raster(p, z);
  }
}

void DepthBuffer::raster(const Eigen::Vector2d* p, const double* z) {
  const double area = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, int(std::ceil(std::min({p[0].x(), p[1].x(), p[2].x()}))));
  const int x1 = std::min(width_ - 1, int(std::floor(std::max({p[0].x(), p[1].x(), p[2].x()}))));
  const int y0 = std::max(0, int(std::ceil(std::min({p[0].y(), p[1].y(), p[2].y()}))));
  const int y1 = std::min(height_ - 1, int(std::floor(std::max({p[0].y(), p[1].y(), p[2].y()}))));
  if (x0 > x1 || y0 > y1) return;
  mark(x0, y0, x1, y1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d q(x, y);
      const auto edge = [&](int i, int j) {
        return ((p[j] - p[i]).x() * (q - p[i]).y() - (p[j] - p[i]).y() * (q - p[i]).x()) / area;
      };
      const double l0 = edge(1, 2), l1 = edge(2, 0), l2 = edge(0, 1);
      if (l0 < 0 || l1 < 0 || l2 < 0) continue;
      float& d = depth_[std::size_t(y) * width_ + x];
      d = std::min(d, float(l0 * z[0] + l1 * z[1] + l2 * z[2]));
    }
  }
}

std::optional<Observation> observe(const SampledView& v, const DepthBuffer& depth,
                                   const Eigen::Vector3d& x, const Eigen::Vector3d& n,
                                   double min_cos, double tolerance, int radius_px) {
  const Eigen::Vector3d to_cam = (v.centre - x).normalized();
  const double cos = n.dot(to_cam);
  if (cos < min_cos) return std::nullopt;
  Eigen::Vector3d xc;
  Eigen::Vector2d p;
  if (!v.project(x, &p, &xc)) return std::nullopt;
  const int W = v.camera->width, H = v.camera->height;
  const long xn = nearest_pixel(p.x()), yn = nearest_pixel(p.y());
  if (xn < 0 || yn < 0 || xn >= W || yn >= H) return std::nullopt;
  if (xc.z() > depth.at(xn, yn) + tolerance) return std::nullopt;
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  const int r = radius_px;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const double px = p.x() + dx, py = p.y() + dy;
      const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= W || y0 + 1 >= H) return std::nullopt;
      if (!v.inside(x0, y0) || !v.inside(x0 + 1, y0) || !v.inside(x0, y0 + 1) ||
          !v.inside(x0 + 1, y0 + 1)) {
        return std::nullopt;
      }
      const double fx = px - x0, fy = py - y0;
      const auto add = [&](int xx, int yy, double w) {
        const Rgb8 q = v.image.row(yy)[xx];
        c += float(w) * Eigen::Vector3f(q.r, q.g, q.b);
      };
      add(x0, y0, (1 - fx) * (1 - fy));
      add(x0 + 1, y0, fx * (1 - fy));
      add(x0, y0 + 1, (1 - fx) * fy);
      add(x0 + 1, y0 + 1, fx * fy);
    }
  }
  c /= float((2 * r + 1) * (2 * r + 1));
  return Observation{c, float(cos * cos), float(cos)};
}

std::vector<float> observe_patch(const SampledView& v, const DepthBuffer& depth,
                                 const Eigen::Vector3d& x, const Eigen::Vector3d& n, double min_cos,
                                 double tolerance, int h, double spacing) {
  std::vector<float> out;
  if (!observe(v, depth, x, n, min_cos, tolerance)) return out;
  // Tangent basis: t1 horizontal where possible (stable between neighbouring voxels).
  Eigen::Vector3d t1 = n.cross(Eigen::Vector3d::UnitY());
  if (t1.squaredNorm() < 1e-6) t1 = n.cross(Eigen::Vector3d::UnitX());
  t1.normalize();
  const Eigen::Vector3d t2 = n.cross(t1);
  const int W = v.camera->width, H = v.camera->height;
  out.reserve(std::size_t((2 * h + 1) * (2 * h + 1)));
  // The lattice in the camera frame is affine in (i, j): its centre and two steps, rotated once
  // (without distortion; else each point through the full projection).
  const Eigen::Vector3d c0 = v.R * x + v.t, ci = v.R * (spacing * t1), cj = v.R * (spacing * t2);
  for (int j = -h; j <= h; ++j) {
    for (int i = -h; i <= h; ++i) {
      Eigen::Vector2d p;
      if (v.pinhole) {
        const Eigen::Vector3d xc = c0 + double(i) * ci + double(j) * cj;
        if (!(xc.z() > 0)) return {};
        const double u = xc.x() / xc.z(), w = xc.y() / xc.z();
        p = Eigen::Vector2d(v.k.fx * u + v.k.skew * w + v.k.cx, v.k.fy * w + v.k.cy);
      } else if (!v.project(x + spacing * (i * t1 + j * t2), &p)) {
        return {};
      }
      const int x0 = int(std::floor(p.x())), y0 = int(std::floor(p.y()));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= W || y0 + 1 >= H) return {};
      if (!v.inside(x0, y0) || !v.inside(x0 + 1, y0) || !v.inside(x0, y0 + 1) ||
          !v.inside(x0 + 1, y0 + 1)) {
        return {};
      }
      const double fx = p.x() - x0, fy = p.y() - y0;
      const auto lum = [&](int xx, int yy) {
        const Rgb8 q = v.image.row(yy)[xx];
        return 0.3 * q.r + 0.6 * q.g + 0.1 * q.b;
      };
      out.push_back(float((1 - fy) * ((1 - fx) * lum(x0, y0) + fx * lum(x0 + 1, y0)) +
                          fy * ((1 - fx) * lum(x0, y0 + 1) + fx * lum(x0 + 1, y0 + 1))));
    }
  }
  return out;
}

std::optional<double> ncc(std::span<const float> a, std::span<const float> b, double min_std) {
  const std::size_t n = a.size();
  if (n == 0 || b.size() != n) return std::nullopt;
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < n; ++k) ma += a[k], mb += b[k];
  ma /= double(n), mb /= double(n);
  double saa = 0, sbb = 0, sab = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double da = a[k] - ma, db = b[k] - mb;
    saa += da * da, sbb += db * db, sab += da * db;
  }
  const double floor2 = min_std * min_std * double(n);
  if (saa < floor2 || sbb < floor2) return std::nullopt;
  return sab / std::sqrt(saa * sbb);
}

double colour_spread(std::span<const Observation> obs) {
  double sw = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Observation& o : obs) {
    sw += o.weight;
    mean += o.weight * o.colour.cast<double>();
  }
  if (sw <= 0) return 0;
  mean /= sw;
  double var = 0;
  for (const Observation& o : obs) {
    const Eigen::Vector3d d = o.colour.cast<double>() - mean;
    var += o.weight * (d.x() * d.x() + d.y() * d.y() + 0.25 * d.z() * d.z());
  }
  return std::sqrt(var / sw / 2.25);
}

}  // namespace studio::offline

#pragma once
// What the photo-consistency test and the texture blend share: a camera prepared for colour
// sampling (its silhouette's interior, away from the blue spill on the edges), a depth buffer for
// visibility, and the colour of a surface point in one camera.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "hull/segment_mesh.h"
#include "offline/photo_carve.h"

namespace studio::offline {

// The nearest pixel of an image coordinate: std::lround's rounding (halves away from zero) without
// its library call (millions a frame); far off (beyond 1e9) or NaN: -1e9 or 1e9, outside any image.
inline long nearest_pixel(double v) {
  if (!(v > -1e9 && v < 1e9)) return v > 0 ? 1000000000L : -1000000000L;
  return long(v >= 0 ? v + 0.5 : v - 0.5);
}

struct SampledView {
  const Camera* camera = nullptr;
  Eigen::Matrix3d R;  // cam_from_world
  Eigen::Vector3d t;
  Eigen::Vector3d centre;  // camera centre in the world
  Intrinsics k;
  bool pinhole = true;  // no lens distortion: project() evaluates K itself
  ImageView<const Rgb8> image;
  // 1 where the pixel and every pixel within edge_margin (Chebyshev) are inside the silhouette:
  // colours are sampled there only (the silhouette border carries the cloth's blue spill).
  std::vector<uint8_t> interior;
  bool inside(int x, int y) const { return interior[std::size_t(y) * camera->width + x] != 0; }
  // x's camera-frame point (*xc) and, when it lies in front (z > 0), its pixel: Camera::project
  // with the rotation as a matrix and, without distortion, K applied here (the carve, the surface
  // stage and the texture project millions of points a frame; the quaternion rotation and the
  // distortion model's checks were a fifth of it). Equal to Camera::project up to rounding.
  bool project(const Eigen::Vector3d& x, Eigen::Vector2d* pixel, Eigen::Vector3d* xc) const {
    *xc = R * x + t;
    if (!(xc->z() > 0)) return false;
    if (!pinhole) return camera->project(x, pixel);
    const double u = xc->x() / xc->z(), w = xc->y() / xc->z();
    *pixel = Eigen::Vector2d(k.fx * u + k.skew * w + k.cx, k.fy * w + k.cy);
    return true;
  }
  bool project(const Eigen::Vector3d& x, Eigen::Vector2d* pixel) const {
    Eigen::Vector3d xc;
    return project(x, pixel, &xc);
  }
};

// Fails on no views or a size mismatch between a camera and its image or mask.
Expected<std::vector<SampledView>> prepare_views(std::span<const ColourView> views,
                                                 int edge_margin_px);

// Nearest camera-frame depth per pixel (infinity where nothing was drawn).
class DepthBuffer {
 public:
  void reset(const SampledView& v);
  // A cube of edge `size` at x, drawn as the square of its projected size around its centre.
  void splat(const SampledView& v, const Eigen::Vector3d& x, double size);
  // Every triangle of `m` whose vertices are all in front, depth interpolated linearly in screen
  // space (perspective error well below a cell for the small triangles of a hull mesh); each
  // vertex projected once.
  void mesh(const SampledView& v, const hull::Mesh& m);
  float at(int x, int y) const { return depth_[std::size_t(y) * std::size_t(width_) + x]; }
  // The pixels drawn since reset() lie in [x0, x1] x [y0, y1] (empty: x1 < x0); infinity elsewhere.
  struct Rect {
    int x0, y0, x1, y1;
  };
  Rect drawn() const { return {dirty_x0_, dirty_y0_, dirty_x1_, dirty_y1_}; }

 private:
  void mark(int x0, int y0, int x1, int y1);               // grows the drawn rectangle
  void raster(const Eigen::Vector2d* p, const double* z);  // a projected triangle
  std::vector<Eigen::Vector2d> projected_;                 // mesh(): each vertex's pixel ...
  std::vector<double> depth_of_;                           // ... and camera depth (<= 0: behind)
  int width_ = 0, height_ = 0;
  std::vector<float> depth_;
  int dirty_x0_ = 0, dirty_y0_ = 0, dirty_x1_ = -1, dirty_y1_ = -1;  // drawn since reset()
};

struct Observation {
  Eigen::Vector3f colour;  // display RGB (0..255), bilinear at the projection
  float weight = 0;        // cos^2 of the viewing angle
  float cos = 0;
};

// The colour camera `v` sees at surface point x with outward normal n, if it sees it: in front,
// cos(n, to camera) >= min_cos, not hidden (depth <= buffer + tolerance, metres), and the
// bilinear footprint lies in the silhouette's interior. radius_px > 0: the mean of the bilinear
// samples on a (2r+1)^2 pixel lattice around the projection (less noise; all in the interior).
std::optional<Observation> observe(const SampledView& v, const DepthBuffer& depth,
                                   const Eigen::Vector3d& x, const Eigen::Vector3d& n,
                                   double min_cos, double tolerance, int radius_px = 0);

// A small square patch on the tangent plane of x (normal n): (2h+1)^2 points spaced `spacing`
// metres, projected into camera v and sampled (bilinear, luminance 0.3 R + 0.6 G + 0.1 B: the
// blue LED ring and the spill tint mostly blue). Empty when v does not see x (as observe()) or
// any sample's footprint leaves the silhouette's interior.
std::vector<float> observe_patch(const SampledView& v, const DepthBuffer& depth,
                                 const Eigen::Vector3d& x, const Eigen::Vector3d& n, double min_cos,
                                 double tolerance, int h, double spacing);

// Zero-mean normalised cross-correlation of two patches of equal size; nullopt when either's
// standard deviation is below min_std (no shading structure to compare: a uniform patch says
// nothing).
std::optional<double> ncc(std::span<const float> a, std::span<const float> b, double min_std);

// Weighted RMS distance of the observations' colours from their weighted mean, blue channel at
// half weight (grey levels).
double colour_spread(std::span<const Observation> obs);

}  // namespace studio::offline

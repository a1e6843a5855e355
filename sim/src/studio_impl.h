#pragma once
// Private to the simulated studio: per-camera caches and the per-frame state shared by
// studio.cc (caches, background, noise, threads) and render.cc (actor, shadow, shading).

#include <array>
#include <vector>

#include "sim/studio.h"

namespace studio::sim::detail {

// Pixel rectangle [x0, x1) x [y0, y1); empty when x0 >= x1 or y0 >= y1.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
  Rect united(const Rect& o) const {
    if (empty()) return o;
    if (o.empty()) return *this;
    return {std::min(x0, o.x0), std::min(y0, o.y0), std::max(x1, o.x1), std::max(y1, o.y1)};
  }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

enum Surface : uint8_t { kNone = 0, kFloor = 1, kWall = 2 };

struct CameraCache {
  Camera camera;
  bool pinhole = true;                // no distortion: rays computed from K on the fly
  std::vector<Eigen::Vector2d> rays;  // distorted cameras: ideal normalised (x, y) per pixel
  Eigen::Matrix3d R;                  // cam_from_world rotation
  Eigen::Vector3d t;
  Eigen::Vector3d centre;             // camera centre in the world
  Image<Rgb8> background;             // noiseless empty studio
  std::array<float, 3> response{1, 1, 1};  // StudioOptions::camera_response (linear gains)
  Image<uint8_t> surface;             // Surface per pixel
  // World (x, z) where each floor pixel's ray meets the floor (y = 0); NaN off the floor. Static
  // per camera: the per-frame shadow (apply_shadow) reads it instead of intersecting the ray.
  std::vector<Eigen::Vector2d> floor_xz;

  // Ideal normalised coordinates (camera-frame ray direction with z = 1) of pixel (u, v).
  Eigen::Vector3d ray(int u, int v) const {
    if (!pinhole) {
      const Eigen::Vector2d& r = rays[static_cast<std::size_t>(v) * camera.width + u];
      return {r.x(), r.y(), 1.0};
    }
    const auto& k = camera.intrinsics;
    const double y = (v - k.cy) / k.fy;
    return {(u - k.cx - k.skew * y) / k.fx, y, 1.0};
  }
  // Conservative pixel rectangle covering the projection of the convex hull of camera-frame
  // points (full image if any is closer than 5 cm or behind), expanded by `margin` pixels.
  Rect project_hull(const Eigen::Vector3d* points, int n, int margin) const;
};

// The actor's floor shadow for one instant: attenuation factors on a grid over a floor box.
struct ShadowMap {
  double x0 = 0, z0 = 0, cell = 0.04;
  int nx = 0, nz = 0;
  std::vector<float> factor;  // 1 = lit, < 1 shadowed; row-major in z
  bool empty() const { return nx == 0 || nz == 0; }
  float at(double x, double z) const;  // bilinear; 1 outside
};

struct PreparedFrame {
  FrameTruth truth;
  std::vector<ActorBody> blur_bodies;  // motion blur sub-instants (empty without blur)
  ShadowMap shadow;
};

// Lights of the studio (world frame, unit), shared by shading and shadows.
inline const Eigen::Vector3d kKeyLight = Eigen::Vector3d(0.4, 1.0, 0.5).normalized();
inline const Eigen::Vector3d kFillLight = Eigen::Vector3d(-0.5, 0.4, -0.3).normalized();

ShadowMap make_shadow(const ActorBody& body, double strength);
// The pixels apply_shadow may darken (empty without a shadow).
Rect shadow_rect(const CameraCache& cam, const ShadowMap& shadow);
// Darkens the camera's floor pixels in the shadow. `cull` (pinhole cameras only): visit only
// the pixels of each row whose floor point may lie on the map (same pixels changed).
void apply_shadow(const CameraCache& cam, const ShadowMap& shadow, Image<Rgb8>* image, bool cull);
// The pixels render_actor may change for this frame and camera (actor rectangles grown by one
// pixel, and the shadow's): outside it the image stays the camera's background.
Rect touched_rect(const StudioOptions& options, const CameraCache& cam, const PreparedFrame& frame);
// Draws shadow, actor (true mask, and the true matte when not null), spill, anti-aliasing or
// motion blur into image / mask / matte, which already hold the camera's background and zeros.
void render_actor(const StudioOptions& options, const CameraCache& cam, const PreparedFrame& frame,
                  Image<Rgb8>* image, Mask* mask, Image<uint8_t>* matte);

}  // namespace studio::sim::detail

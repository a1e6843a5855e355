#pragma once
// What one data projector must draw so that the actor, at the eye position, sees the virtual scene
// through its screen rectangle (TCSVT 2004 §V-C/D): the off-axis view from the eye onto the
// screen (projector/off_axis.h) combined with the 8-parameter homography between the screen plane
// and the projector image. A projector is an inverse camera (DESIGN §1): its calibration K and
// cam_from_world (core/rig.h Projector) map a point of the screen plane to the projector pixel
// that lights it; restricted to the plane X = origin + s vr + t vu this is the homography
//   ideal pixel ~ H (s, t, 1)^T,  H = K [R vr | R vu | R origin + t]     (8 dof, exact)
//
// Two forms, same geometry (chosen by the projector node's config):
// - single pass (the paper's): H folded into the eye's projection, one 4x4 clip_from_world that
//   maps a world point straight to the projector's clip space. With the eye's clip coordinates
//   (x, y, z, w) and G = ndc_from_pixel * H * screen_from_eye_ndc (3x3), the projector clip
//   coordinates are x' = G0 . (x, y, w), y' = G1 . (x, y, w), w' = G2 . (x, y, w), z' = z.
//   w' / w = k(s, t) > 0 is constant along every eye ray (it depends on the screen point only), so
//   z' / w' = NDC_z(eye) / k keeps the depth order of everything a projector pixel sees (one
//   projector pixel = one screen point = one eye ray). G is scaled so that k >= 1 on the screen
//   rectangle, which keeps the eye's [near, far] range inside NDC z in [-1, 1] there. Points
//   behind the eye are not reliably clipped by w' alone: the renderer must also clip with
//   `eye_clip_plane` (gl_ClipDistance[0] = dot(eye_clip_plane, vec4(world, 1)), kept where >= 0).
//   Lens distortion cannot be folded into a matrix: the single-pass form refuses a projector with
//   distortion (use the two-pass form).
// - two pass: render the eye's off-axis view (`eye.clip_from_world`) into a texture that covers the
//   screen rectangle exactly (texture (0, 0) = lower-left corner, (1, 1) = upper-right), then draw
//   the projector image with one full-screen quad that samples it at the texture coordinates of
//   each projector pixel: h = texture_from_ndc * (ndc_x, ndc_y, 1) interpolated linearly (the
//   vertex shader emits it for the quad corners, w = 1), texture(tex, h.xy / h.z) in the fragment
//   shader, black where the result is outside [0, 1]^2 (no cloth there). For a projector with lens
//   distortion the 3x3 is not exact: sample `warp_map()` (per-pixel texture coordinates, exact)
//   instead.
//
// Pixel and NDC conventions (core/camera.h): pixel (0, 0) is the centre of the top-left pixel, v
// grows downwards; projector NDC x = (2u + 1) / W - 1, y = 1 - (2v + 1) / H, so NDC y is up and
// image row v is the GL framebuffer row H - 1 - v (gl_FragCoord = (u + 0.5, H - v - 0.5)). A
// renderer that reads the framebuffer back bottom-up flips it to get the projector image.

#include <Eigen/Core>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/rig.h"
#include "projector/off_axis.h"
#include "projector/screen.h"

namespace studio::projector {

// Projector NDC <-> observed pixel, as 3x3 affine maps (conventions above).
Eigen::Matrix3d ndc_from_pixel(int width, int height);
Eigen::Matrix3d pixel_from_ndc(int width, int height);

struct SinglePass {
  OffAxisView eye;                  // the eye's own view (for reference and tests)
  Eigen::Matrix4d clip_from_world;  // projector clip space, see above
  Eigen::Vector4d eye_clip_plane;   // world plane, >= 0 in front of the eye's near plane
};

struct TwoPass {
  OffAxisView eye;                         // pass 1: eye.clip_from_world renders the screen texture
  Eigen::Matrix3d texture_from_pixel;      // projector ideal pixel -> screen texture (homogeneous)
  Eigen::Matrix3d pixel_from_texture;      // its inverse
  Eigen::Matrix3d texture_from_ndc;        // projector NDC -> screen texture (for the quad)
  Eigen::Matrix3d texture_from_fragcoord;  // gl_FragCoord.xy (bottom-left origin) -> texture
  bool exact = true;  // false when the projector has lens distortion: use warp_map() instead
};

class ProjectorView {
 public:
  // Eye-independent part: the fitted screen and the homography. Errors: invalid camera (size,
  // focal length, non-finite pose), degenerate screen (projector/screen.h), and a projector that
  // does not see its screen: a corner behind (or at) the projector's centre plane, the projector
  // behind the screen (lighting the back of the cloth), or the screen entirely outside the
  // projector image.
  static Expected<ProjectorView> create(const Projector& projector,
                                        const ScreenOptions& screen_options = {});

  const Camera& camera() const { return camera_; }
  const Screen& screen() const { return screen_; }
  // Ideal (undistorted) projector pixel ~ pixel_from_screen * (s, t, 1).
  const Eigen::Matrix3d& pixel_from_screen() const { return pixel_from_screen_; }
  const Eigen::Matrix3d& screen_from_pixel() const { return screen_from_pixel_; }

  // Screen coordinates lit by an observed projector pixel (lens distortion removed first).
  Eigen::Vector2d screen_from_observed_pixel(const Eigen::Vector2d& pixel) const;
  // Texture coordinates of every projector pixel, row-major from the top row (v = 0), two floats
  // (s / width, t / height) per pixel; exact with lens distortion. 2 * W * H floats.
  std::vector<float> warp_map() const;
  // Size (columns, rows) of the eye texture that keeps at least one texel per projector pixel
  // along both screen edges (the longest projected edge of the screen, rounded up).
  Eigen::Vector2i suggested_texture_size() const;

  // Errors: those of off_axis_view(); single_pass() also refuses a projector with distortion.
  Expected<SinglePass> single_pass(const Eigen::Vector3d& eye,
                                   const OffAxisOptions& options = {}) const;
  Expected<TwoPass> two_pass(const Eigen::Vector3d& eye, const OffAxisOptions& options = {}) const;

 private:
  Camera camera_;
  Screen screen_;
  Eigen::Matrix3d pixel_from_screen_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d screen_from_pixel_ = Eigen::Matrix3d::Identity();
};

}  // namespace studio::projector

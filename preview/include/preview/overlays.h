#pragma once
// What the preview's 3D view draws over the scene and the actor (issue 16: "head marker; camera
// and projector frusta; what each projector is showing"), as world-frame geometry: line
// segments, spheres and projector screens. Pure: the GL side (preview/gl/overlay_renderer.h)
// draws what this returns.
//
//   head marker     the tracked head (studio/actor/head, the eye the projectors render from,
//                   TCSVT 2004 §V-E): a sphere of `head_radius_m` at its position, its velocity
//                   as a line (where it will be in `velocity_lead_s`), and sight lines from it to
//                   the centre of every projector's screen (each projector shows the scene as
//                   seen from this eye through its screen). HeadPose carries no orientation, so
//                   the marker shows no gaze of its own.
//   camera frustum  a studio camera's viewing pyramid (studio/camera/calibration): its centre to
//                   the rays of the four image corners, cut at `camera_frustum_m` along its axis
//                   (camera z), the cut's rectangle, and a tick above the image's top edge (which
//                   way is up in its picture).
//   projector       the projector's centre to the four corners of the screen it lights and the
//                   screen's outline (studio/projector/calibration: corners lower-left,
//                   lower-right, upper-right, upper-left).
//   screen          the screen rectangle textured with what the projector shows: each screen
//                   point x takes the projector's latest thumbnail (studio/projector/frame, the
//                   whole projector frame scaled) at the projector pixel K [R | t] x, as the
//                   cloth would be lit; screen points outside the projector's image stay dark.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/rig.h"

namespace studio::preview {

struct OverlayOptions {
  bool head = true;               // head marker (with its velocity and sight lines)
  bool camera_frusta = true;      // every studio camera's frustum
  bool projector_frusta = true;   // every projector's frustum to its screen
  bool projector_screens = true;  // every screen textured with its projector's thumbnail
  double camera_frustum_m = 0.5;  // depth (camera z, metres) at which camera frusta are cut
  double head_radius_m = 0.09;
  double velocity_lead_s = 0.5;
  Expected<void> validate() const;
};

struct HeadMarker {
  std::string actor_id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // studio frame, metres
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // metres per second
  double confidence = 0;
};

struct OverlaySegment {
  Eigen::Vector3f a = Eigen::Vector3f::Zero(), b = Eigen::Vector3f::Zero();
  Eigen::Vector3f colour = Eigen::Vector3f::Ones();
};
struct OverlaySphere {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  float radius = 0;
  Eigen::Vector3f colour = Eigen::Vector3f::Ones();
};
// A projector's screen to texture: corners (lower-left, lower-right, upper-right, upper-left)
// and the projector's camera (pixel of a world point: its K [R | t]; size of its frame).
struct OverlayScreen {
  std::string projector_id;
  std::array<Eigen::Vector3d, 4> corners;
  Camera projector;
};

struct OverlayGeometry {
  std::vector<OverlaySegment> lines;
  std::vector<OverlaySphere> spheres;
  std::vector<OverlayScreen> screens;
};

// The overlays' colours (RGB, 0..1): distinct from each other and from the backing blue.
namespace overlay_colour {
inline const Eigen::Vector3f head{1.0f, 0.85f, 0.0f};      // yellow sphere
inline const Eigen::Vector3f velocity{1.0f, 0.45f, 0.0f};  // orange
inline const Eigen::Vector3f sight{0.85f, 0.85f, 0.55f};   // pale yellow
inline const Eigen::Vector3f camera{0.0f, 1.0f, 1.0f};     // cyan
inline const Eigen::Vector3f projector{1.0f, 0.0f, 1.0f};  // magenta
inline const Eigen::Vector3f screen_unlit{0.12f, 0.12f, 0.12f};
}  // namespace overlay_colour

// The frustum of a studio camera cut at `depth_m` (camera z): 4 edges from the centre, the
// cut's 4 sides, and the "up" tick (2 segments): 10 segments. Image corners are the outer
// corners of the corner pixels, (-0.5, -0.5) .. (width - 0.5, height - 0.5).
std::vector<OverlaySegment> camera_frustum(const Camera& camera, double depth_m);
// A projector's frustum: its centre to each screen corner and the screen's outline (8 segments).
std::vector<OverlaySegment> projector_frustum(const Projector& projector);
// All overlays the options switch on, for these cameras, projectors and heads.
OverlayGeometry build_overlays(const OverlayOptions& options, const std::vector<Camera>& cameras,
                               const std::vector<Projector>& projectors,
                               const std::vector<HeadMarker>& heads);

// "head,cameras,projectors,screens" (any subset, comma separated; "all" or "none") → the four
// switches of `options`. Error: the unknown word.
Expected<void> parse_overlay_list(const std::string& list, OverlayOptions& options);

}  // namespace studio::preview

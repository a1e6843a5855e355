#pragma once
// Projector light in the simulated studio: the truth the projector service (TCSVT 2004 §V-C/D)
// is scored against (issue 15 item 5). Computed here with the simulator's own maths — a plain
// pinhole for the projector, its own ray/box intersection for the cyclorama, the actor's analytic
// solids for the body — and never with projector/'s library, so an error there cannot cancel
// against the same error here.
//
// A projector is an inverse camera (core/rig.h Projector: K, cam_from_world, size; no lens
// distortion here). Projector pixel (u, v) (pixel-centre convention of core/camera.h: pixel
// (0, 0) is the centre of the top-left pixel) is the square [u - 0.5, u + 0.5) x [v - 0.5,
// v + 0.5) of uniform colour frame(u, v); a world point X is lit by the pixel its projection
// falls in, when X is in front of the projector and nothing (a board, the actor when given) lies
// on the segment from the projector centre to X.
//
// Three views of that light:
// (a) eye_view(): what the actor sees — the light on the cloth seen from the true eye (a camera
//     at the eye); the cloth's diffuse return towards the eye is `eye_gain` of the frame's value.
// (b) actor_in_projector() / actor_at_display(): the projector pixels whose ray meets the true
//     actor, at the instant the frame is on the cloth (render time + a non-zero display lag).
//     A probe computes lit-actor pixels = that mask AND NOT the projector's blackout mask, and
//     wasted pixels = blackout AND NOT that mask (count_lit()).
// (c) the studio cameras' view of the projected light (StudioOptions::projector_light, drawn into
//     each camera's cyclorama background by sim/studio.cc): the retro-reflective cloth returns
//     most of the projector's light to the projector, a studio camera receives `cloth_gain` of it
//     and mostly its own LED ring's light (`ring_level` scales it). With the ring light off or
//     dimmed and a longer `exposure` the pattern becomes visible (projector calibration does
//     this, paper §III-C). Boards held in the beam (diffuse, calibration) are lit `board_gain`.
//     Limitation: the actor's own shadow on the cloth is not drawn in camera images (the
//     background is static per studio), which makes keying harder, not easier.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "core/rig.h"
#include "core/run_mask.h"
#include "sim/actor.h"

namespace studio::sim {

// One projector of the simulated studio and the frame it shows (empty frame: black).
struct SimProjector {
  Projector projector;  // camera (K, cam_from_world, size; no distortion) + screen corners
  Image<Rgb8> frame;
};

// A flat diffuse board held in the projector's beam (calibration): the rectangle
// centre + a x_axis + b y_axis with |a| <= half_width, |b| <= half_height (axes unit, orthogonal).
struct Board {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = Eigen::Vector3d::UnitY();
  double half_width = 0.5, half_height = 0.4;
  double albedo = 0.85;
};

struct ProjectorLight {
  std::vector<SimProjector> projectors;
  std::vector<Board> boards;
  double ring_level = 1;        // the cameras' LED ring, 0 (off) .. 1 (normal)
  double exposure = 1;          // relative exposure of the studio cameras, (0, 16]
  double cloth_gain = 0.12;     // fraction of the projector's light the cloth returns to a camera
  double board_gain = 0.7;      // ... a diffuse board (times its albedo)
  double board_ambient = 0.12;  // the board under the studio's own light, fraction of white
  double eye_gain = 1;          // (a): fraction the cloth returns towards the actor's eye
  int samples = 3;  // n x n rays per camera pixel where projector light is drawn, [1, 8]
  bool empty() const { return projectors.empty() && boards.empty(); }
  // Sizes, finiteness, no distortion, frames empty or of the projector's size, gains in range.
  Expected<void> validate() const;
};

// The cyclorama as the simulator models it (sim/studio.h): floor y = 0 and the four walls of
// |x|, |z| <= half_width, 0 <= y <= height.
struct Cyclorama {
  double half_width = 4.5, height = 4.0;
};

struct SurfaceHit {
  double t = 0;            // ray parameter
  Eigen::Vector3d point;   // world
  Eigen::Vector3d normal;  // unit, facing the ray's origin side
  int board = -1;          // index into boards, -1 for the cloth
  bool floor = false;
};

// Nearest of the boards and the cloth along origin + t dir (t > 0), if any.
std::optional<SurfaceHit> hit_surface(const Cyclorama& cyc, const std::vector<Board>& boards,
                                      const Eigen::Vector3d& origin, const Eigen::Vector3d& dir);

// Linear light (0..255 scale of the frames' values, summed over projectors) arriving at point X
// of surface `board` (-1: the cloth): per projector, frame(pixel of X) when X is in front of it,
// inside its image, and neither another board nor `occluder` (if given) blocks the segment.
std::array<double, 3> projected_light(const ProjectorLight& light, const Eigen::Vector3d& X,
                                      int board, const ActorBody* occluder = nullptr);

// (a) The actor's view through `eye` (a camera at the true eye): per pixel, eye_gain times the
// projector light on the cloth (or board) the pixel's ray meets, n x n supersampled (samples),
// quantised; `lit` marks pixels where at least one sample is lit by a projector. The actor's body
// casts its shadow on the cloth when `occluder` is given; eye rays themselves ignore the body.
struct EyeView {
  Image<Rgb8> image;
  Mask lit;
};
EyeView eye_view(const ProjectorLight& light, const Cyclorama& cyc, const Camera& eye,
                 const ActorBody* occluder = nullptr);

// (b) 255 where the ray of projector pixel (u, v) (through its centre) meets the actor's solid.
// Exact per pixel; cast only inside the projected bounds of each part.
Mask actor_in_projector(const Camera& projector, const ActorBody& body);

struct DisplayOptions {
  double display_lag_s = 0.016;  // frame rendered → frame on the cloth; > 0 (a display has one)
  Expected<void> validate() const;
};
// The true actor in the projector's image at the instant the frame rendered at `render_time_s`
// (studio time, sim/studio.h: frame f is t = f / fps) is shown: actor at render_time + lag.
Mask actor_at_display(const Actor& actor, const Camera& projector, double render_time_s,
                      const DisplayOptions& options);

struct LitCount {
  uint64_t actor = 0;      // projector pixels on the true actor
  uint64_t lit_actor = 0;  // on the actor and not blacked out: light on the actor
  uint64_t blackout = 0;   // blacked-out pixels
  uint64_t wasted = 0;     // blacked out but off the actor: scene lost for nothing
};
// Both of the projector's size (a programming error otherwise: throws std::invalid_argument).
LitCount count_lit(const Mask& actor, const RunMask& blackout);

// A projector placed for the simulated studio: at `centre`, looking at `target` (by default the
// middle of the back wall, z = -half_width) so that its image spans `wall_width_m` at the target's
// distance, width x height pixels, principal point at the image centre, no distortion; the screen
// corners are where the image's corner rays meet the wall plane through the target (x = target.x
// or z = target.z, the larger in magnitude), clipped to the cloth's height. Used by tests, the demo
// and calibration checks.
Projector studio_projector(const Cyclorama& cyc, const Eigen::Vector3d& centre,
                           double wall_width_m = 6.0, int width = 1920, int height = 1080,
                           const Eigen::Vector3d& target = Eigen::Vector3d(0, 1.6, -4.5),
                           const std::string& id = "proj0");

}  // namespace studio::sim

#pragma once
// The simulated studio (issue 3 item 1): N calibrated virtual cameras around an animated
// articulated actor (sim/actor.h) on a blue retro-reflective cyclorama, producing per
// frame the camera images, the TRUE masks and the true actor geometry / head centre. It is the
// ground truth the keyer, the visual hull, the head tracker and calibration are scored against.
//
// Contracts
// - True mask: pixel (u, v) is 255 iff the ray through the pixel CENTRE (studio::Camera
//   convention: pixel (0,0) is the centre of the top-left pixel; distortion honoured) hits the
//   actor's solid at the frame's instant, 0 otherwise. Exact, not anti-aliased: the geometric
//   silhouette the visual hull is scored against.
// - True matte: per pixel, the fraction (0..255) of the image's own sub-samples (over the
//   pixel's area and, with motion blur, the shutter) that see the actor: the alpha a perfect
//   keyer would recover from the image. It differs from the true mask only where the silhouette
//   crosses a pixel, and where motion blur smears it (a part moving further than its own width
//   during the exposure covers no pixel for more than half of it).
// - Image: RGB, the cyclorama seen by the camera with realism knobs (all modest and on by
//   default except motion blur and the projected image): sensor noise, illumination fall-off
//   on the cloth (vignetting, distance and angle of the retro-reflection, seams), blue spill on
//   the actor's edges, soft shadows of the actor on the floor, anti-aliased silhouette edges
//   (area-integrated: see aa_samples). Motion blur integrates each pixel over the shutter.
//   Background pixels are keyable: blue dominates (b > r + 60 and b > g + 60 before noise).
// - Determinism: image and mask depend only on (cameras, options, frame); threads change nothing.
// - Time: frame f shows the instant t = f / fps (motion blur integrates around it).
// - Cyclorama: floor (y = 0) and four walls of an open-topped box |x|, |z| <= half_width,
//   0 <= y <= height, larger than the 3 m x 3 m x 3 m acting area so that ring cameras see cloth
//   everywhere. Rays leaving the box see a dark studio (not keyable as blue).
// Speed: the background (cloth, fall-off, seams, projected image) is cached per camera; per
// frame only the actor's projected bounding rectangles are ray cast, the shadow is a small
// floor map, noise comes from a table at a per-frame offset, and cameras run on `threads`
// threads. Anti-aliasing sub-samples are cast only against the parts a conservative cone test
// cannot rule out for the pixel, and the background copy and the noise are one pass outside
// the rectangle the actor and its shadow touch. See BENCHMARKS.md ("Simulated studio").

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "sim/actor.h"
#include "sim/projector_light.h"

namespace studio::sim {

struct StudioOptions {
  uint64_t seed = 1;  // sensor noise (the actor has its own seed in `actor`)
  double fps = 25;
  Actor::Options actor;

  // Cyclorama.
  double cyclorama_half_width = 4.5;  // metres
  double cyclorama_height = 4.0;
  Rgb8 cloth{30, 66, 212};            // the lit cloth at the image centre, before fall-off

  // Realism knobs (0 disables each).
  double noise_sigma = 2.0;     // Gaussian sensor noise, grey levels per channel
  double cloth_falloff = 0.35;  // darkening of the cloth towards the image edges and far away
  double spill = 0.30;          // blue spill at grazing angles on the actor's edges
  double shadow = 0.40;         // darkness of the actor's soft floor shadow
  double ring_light = 0.12;     // the camera's own blue LED ring lighting the actor
  // Image formation at the silhouette integrates over the pixel's area (and, with motion blur,
  // over the shutter) like a sensor does, with sub-samples spread so that an edge's position
  // is resolved to ~1/samples px in any direction (render.cc: pixel_samples). Which part (or
  // the background) each sub-sample sees is exact; the sub-samples on one part are shaded once,
  // at the one nearest their centroid (render.cc: edge_colour: the shading varies little across
  // a pixel; against shading every sub-sample, ~1 000 edge pixels a camera differ by 1 grey
  // level on average, 15 at most; sim_render_equivalence_test), unless aa_shade_every_sample.
  bool antialias = true;        // area-integrated silhouette edges (the mask stays exact)
  int aa_samples = 16;          // sub-samples per edge pixel, in [2, 64]
  bool aa_shade_every_sample = false;  // shade each sub-sample (~1.2x the render's CPU)
  bool motion_blur = false;     // integrate the actor over the shutter
  double shutter = 0.5;         // exposure as a fraction of the frame period
  int blur_samples = 16;        // instants, in [2, 64]; with antialias each has its own
                                // sub-pixel sample where the silhouette crosses the pixel
  bool projected_image = false;  // a faint projected picture on the back wall (z = -half_width)
  double projection_strength = 0.12;
  Image<Rgb8> projection;        // the projected picture; empty = a built-in test scene
  // Calibrated projectors showing frames on the cloth, boards in the beam, the cameras' ring
  // level and exposure (sim/projector_light.h (c)); the default changes nothing.
  ProjectorLight projector_light;

  bool frame_code = false;  // the actor wears the frame number (sim/frame_code.h)
  // A patterned costume: the clothing parts' albedo (not the skin: head, neck, hands; nor hair)
  // modulated by a fixed pattern on the part's own surface (stripes along each limb, checks
  // round it, a finer weave), 0.6 .. 1.0 of the plain albedo, the same seen from every camera at
  // an instant (round a limb it is laid from a world-fixed direction, so it does not follow the
  // limb's twist over time), hue kept (the key is unaffected). false: plainly coloured clothing
  // (every figure so far).
  bool patterned_costume = false;
  // Each camera's colour response: a linear-light gain per channel (R, G, B) applied to all it
  // sees, cloth and actor (exposure, aperture and white balance: a real rig's cameras differ by a
  // few percent per channel after white balance). Empty: every camera 1, 1, 1 (every figure so
  // far); else one entry per camera, each gain in [0.25, 4]. random_camera_response() draws one.
  std::vector<std::array<double, 3>> camera_response;

  int threads = 2;  // render_all() threads over cameras
  // The renderer as it was before issue 20's cuts (every candidate part ray cast for every
  // anti-aliasing sub-sample; background copy and noise as two whole-image passes; a fresh mask
  // per call). Same images bit for bit, noise included (studio_test: FastRendererMatchesReference);
  // kept as the tests' reference and sim_bench's baseline. Not for production use.
  bool reference_renderer = false;

  Expected<void> validate() const;
};

// A rig's colour responses drawn from `seed`: per camera an exposure factor uniform in
// [1 - exposure_spread, 1 + exposure_spread] times, on red and blue, a white-balance factor
// uniform in [1 - balance_spread, 1 + balance_spread] (green: the balance's reference). Spreads
// in [0, 0.5].
std::vector<std::array<double, 3>> random_camera_response(int cameras, uint64_t seed,
                                                          double exposure_spread,
                                                          double balance_spread);

// The truth a colour balance is scored against: per camera the factors on its 8-bit (display)
// values that bring it to the rig's geometric mean per channel, i.e. (mean / g)^(1/2.2) for
// linear gains g (the display transfer's power law turns a linear gain into its 1/2.2 power).
std::vector<std::array<double, 3>> balancing_gains(
    const std::vector<std::array<double, 3>>& camera_response);

// Ground truth of one frame.
struct FrameTruth {
  int64_t frame = 0;
  double time = 0;
  ActorPose pose;
  ActorBody body;  // the true solid and surface at `time`
  Eigen::Vector3d head_centre() const { return body.head_centre(); }
};

class SimulatedStudio {
 public:
  // Fails with one line on invalid options or cameras (empty list, bad size, bad intrinsics).
  static Expected<SimulatedStudio> create(std::vector<Camera> cameras,
                                          const StudioOptions& options = {});
  SimulatedStudio(SimulatedStudio&&) noexcept;
  SimulatedStudio& operator=(SimulatedStudio&&) noexcept;
  ~SimulatedStudio();

  const StudioOptions& options() const;
  const Actor& actor() const;
  const std::vector<Camera>& cameras() const;
  int camera_count() const { return static_cast<int>(cameras().size()); }
  double time_of(int64_t frame) const { return static_cast<double>(frame) / options().fps; }

  FrameTruth truth(int64_t frame) const;

  // One camera. image, true_mask and true_matte are (re)sized to the camera; any may be null.
  void render(int camera, int64_t frame, Image<Rgb8>* image, Mask* true_mask,
              Image<uint8_t>* true_matte = nullptr) const;
  // All cameras of one frame, `threads` at a time; vectors are resized to camera_count().
  // Returns the frame's ground truth.
  FrameTruth render_all(int64_t frame, std::vector<Image<Rgb8>>* images,
                        std::vector<Mask>* true_masks,
                        std::vector<Image<uint8_t>>* true_mattes = nullptr) const;
  // A moving (tracked) camera: camera `index` takes `camera`'s intrinsics and pose (same size);
  // its cached rays and background are rebuilt, nothing else. Not thread-safe with render().
  Expected<void> set_camera(int index, const Camera& camera);
  // The empty studio as camera `camera` sees it, without noise (for difference keying).
  const Image<Rgb8>& background(int camera) const;

  struct Impl;

 private:
  explicit SimulatedStudio(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::sim

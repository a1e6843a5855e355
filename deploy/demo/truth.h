#pragma once
// The simulator's truth for the demo, frame by frame (the simulated studio is deterministic per
// frame: sim/studio.h; the capture service's sim source renders frame f of its camera as
// SimulatedStudio::render(camera, f) — capture/sim_source.h — with the scene of
// capture::SimSourceOptions's defaults, which is what a `source: {type: sim}` config gets).
//
//   - mesh score: each live actor mesh of frame f rasterised into every camera (pixel centres,
//     hull/testing/raster.h) against that camera's TRUE mask of frame f (the geometric
//     silhouette); IoU per camera, mean over cameras;
//   - head error: distance between a published head position and the true head centre of f.
//   - projector light (issue 15 item 5, sim/projector_light.h): the projector pixels whose ray
//     meets the TRUE actor at the instant a projector frame is on the cloth (render time + the
//     simulator's display lag), and of those the ones the frame's blackout mask leaves lit.
//   - what the actor sees (OUT/actor_view.png): a projector frame's light on the cloth seen from
//     the TRUE eye at its display time (sim::eye_view, the actor's body casting its shadow).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "core/rig.h"
#include "core/run_mask.h"
#include "hull/segment_mesh.h"

namespace studio::demo {

struct MeshScore {
  uint64_t frame = 0;
  double mean_iou = 0;
  double min_iou = 0;
  std::string worst_camera;
};

class TruthScorer {
 public:
  // cameras: as the capture services publish them on studio/camera/calibration.
  static Expected<TruthScorer> create(std::vector<Camera> cameras);
  TruthScorer(TruthScorer&&) noexcept;
  TruthScorer& operator=(TruthScorer&&) noexcept;
  ~TruthScorer();

  // The union of `meshes` (every actor of the frame) against the true masks of `frame`.
  MeshScore score_meshes(uint64_t frame, const std::vector<hull::Mesh>& meshes) const;
  // |position - true head centre of frame|, metres.
  double head_error(uint64_t frame, const Eigen::Vector3d& position) const;
  Eigen::Vector3d true_head(uint64_t frame) const;
  // The true head centre at a fractional frame of the simulator's clock (linear between frames).
  Eigen::Vector3d true_head_at(double studio_frame) const;

  // Projector light on the true actor. `studio_frame` is a fractional frame number of the
  // simulator's clock (frame f is the actor at f / fps, sim/studio.h) for the frame's render
  // time; the actor is taken at that time + display_lag_s (sim::actor_at_display). The blackout
  // mask must be of the projector's size (else an error). `actor_out`, if given, receives the true
  // actor mask (255 on the actor).
  struct Lit {
    uint64_t actor = 0, lit_actor = 0, blackout = 0, wasted = 0;
  };
  Expected<Lit> projector_lit(const Camera& projector, double studio_frame, double display_lag_s,
                              const RunMask& blackout, Mask* actor_out = nullptr) const;

  // What the actor sees when `frame` (the projector's image, of its size) is on the cloth: a
  // width x height camera at the true head centre at studio_frame + display lag, looking at the
  // centre of the projector's screen, 100 degrees across; the cloth is taken as the box whose
  // back wall is the screen's plane (sim::Cyclorama with the screen's |z| as half width).
  Expected<Image<Rgb8>> actor_view(const Projector& projector, double studio_frame,
                                   double display_lag_s, Image<Rgb8> frame, int width = 640,
                                   int height = 360) const;

 private:
  struct Impl;
  explicit TruthScorer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::demo

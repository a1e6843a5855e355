#pragma once
// The projector mask's margin sweep (issue 15, "Mask": lit-actor and wasted pixels against the
// margin, with and without prediction), offline on a recorded sequence of the simulated studio:
// the fast arm swing (sim arm_swing, fingertips at 1.5 m/s) seen by the rig's cameras, TRUE masks
// -> the hull library (visual hull at the live hull's grid, segment marching cubes, exact
// crossings: the mesh the live hull publishes) -> the node's own MaskPlanner (one motion
// estimate per mesh) with floor = cap = the margin under test, prediction on or off -> the mask
// mesh rasterised into the projector (pixel centres) -> against the simulator's true actor in
// the projector's image at display time (sim::actor_at_display).
//
// Timing, as live: mesh of frame f (captured at f / fps) is drawn in a frame rendered latency_s
// later (the motion-to-photon latency MEASURED live by the demo: its p99, so 99 % of live frames
// are no later) and shown display_lag_s after that; with prediction, the mesh is moved forward
// to the render time, as the node does.

#include <string>
#include <vector>

#include "core/error.h"
#include "core/rig.h"

namespace studio::demo {

struct SweepOptions {
  Projector projector;
  std::vector<Camera> cameras;  // the rig's (the simulated ring's own)
  double latency_s = 0.05;      // motion to photon, measured live
  double display_lag_s = 0.016;
  int first_frame = 25;
  int frames = 100;
  int grid = 160;  // hull columns per side, as hull.yaml
  // The mask's growth, as the projector node's mask_growth: true = outline (its default), false
  // = the vertex push.
  bool outline = true;
  Eigen::Vector3d box_min{-1.5, 0, -1.5}, box_max{1.5, 2.4, 1.5};
  std::vector<double> margins_m{0,    0.005, 0.01, 0.015, 0.02, 0.025, 0.03,
                                0.04, 0.05,  0.06, 0.08,  0.1,  0.12};
  Expected<void> validate() const;
};

struct SweepPoint {
  double margin_m = 0;
  uint64_t lit_actor_px = 0;  // summed over frames
  uint64_t max_per_frame = 0;
  int frames_with_lit = 0;
  double wasted_px_mean = 0;  // blacked out but off the true actor, per frame
};

struct SweepCurve {
  bool prediction = false;
  std::vector<SweepPoint> points;
  double needed_margin_m = -1;  // smallest margin of the sweep with 0 lit pixels (-1: none)
};

struct SweepResult {
  SweepOptions options;
  int frames_scored = 0;
  double actor_px_mean = 0;
  double max_speed_mps = 0;  // fastest region the motion estimate saw
  SweepCurve predicted, unpredicted;
};

Expected<SweepResult> margin_sweep(const SweepOptions& options, bool progress = false);
std::string sweep_json(const SweepResult& r);
// Lit-actor (log scale) and wasted pixels against the margin, both curves (OpenCV).
bool draw_sweep_png(const SweepResult& r, const std::string& path);

}  // namespace studio::demo

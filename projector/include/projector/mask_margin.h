#pragma once
// The actor mask's security margin (TCSVT 2004 §V-D: the mesh drawn black from the projector,
// "enlarged by a security margin" for latency and motion), computed instead of guessed.
//
// Latency L: from the capture of the frame whose masks built the mesh (ActorMesh::capture_ns) to
// the moment the projector frame is shown; measured per frame by the node, summarised here by a
// high quantile of a sliding window (LatencyWindow), so the margin covers the slow frames too.
//
// margin = clamp(floor + motion_term, floor, cap), with
//   no prediction:    motion_term = v L + a L^2 / 2
//       v = max(|head velocity|, fastest mesh region) (projector/motion.h); a = the worst case
//       max_acceleration_mps2 (the default, below: an actor may start moving during the latency;
//       without it a fallback to this term, the first mesh, a mesh after a gap or one whose
//       velocities are too old, covered an actor at rest only by the floor), 0 in estimate mode
//   with prediction:  motion_term = a L (L + dt) / 2 + sigma_v L
//       The mesh is moved forward by its regions' mean velocity over the last two captures
//       (dt apart, the velocity at t - dt/2). For a region with constant acceleration a, the true
//       position at t + L differs from x(t) + v_mean L by (v(t) - v_mean) L + a L^2 / 2 =
//       a L (L + dt) / 2. a = the largest region acceleration of the estimate (robust: the
//       median over the tracker's last frames, MeshMotion::robust_acceleration_mps2, when set),
//       at most max_acceleration_mps2; sigma_v the velocity estimate's uncertainty (configured).
//       max_acceleration_mps2 is a physical bound on the actor, not a fit: a human limb in fast
//       stage motion (the simulated arm swing at 1.5 m/s fingertip speed peaks at ~5 m/s^2);
//       8 m/s^2 keeps 60 % headroom over it, and bounds what noise can add to the margin
//       (a L (L + dt) / 2 at L = 0.12 s: 77 mm at most, where unbounded estimates of 15-35
//       m/s^2 from noisy hull meshes put the margin at its cap).
//   The default takes a = max_acceleration_mps2 whatever the estimate (worst_case_acceleration):
//   an actor at rest can start moving at any moment, and an estimate from second differences of
//   meshes sees the onset 2-3 meshes late. With the estimate instead (the median above), the
//   demo's 60 s runs left 183 and 2982 px lit in 2 frames each, at the simulated actor's
//   transitions (0.4 s smoothstep blends between poses: accelerations up to ~15 m/s^2, hence the
//   default bound). The worst case makes the margin a function of latency alone: at the issue's
//   40 ms it is 0.5 * 15 * 0.04 * 0.08 + 0.05 * 0.04 + floor = 36 mm; at 150 ms it is capped.
//   Late latching (projector/mask_planner.h latch_mesh()): a mesh drawn before its own motion
//   is fitted is moved forward by the PREVIOUS fit's velocities (projector/velocity_field.h),
//   which stand for an instant further back. In general, with the velocity standing for the
//   instant `age` before the mesh's capture (velocity_age_s; the mean over a fit's two captures
//   dt apart stands for dt/2 before the later one), the error at t + L is
//   (v(t) - v(t - age)) L + a L^2 / 2 = a L (L + 2 age) / 2; the fresh fit's age = dt/2 gives the
//   formula above, the previous fit's age = (t - t_prev) + dt_prev / 2 (about 1.5 mesh
//   intervals: at 25 Hz and L = 30 ms, 15 * 0.03 * 0.15 / 2 = 34 mm instead of 16 mm).
//   Prediction is used only when the motion has an acceleration estimate (the third mesh on) and
//   agrees with the head tracker (the head is not faster than the fastest region by more than
//   head_disagreement_mps); otherwise the no-prediction term applies.
//   floor: what motion does not explain (the hull's own error, the mesh's resolution, calibration);
//   cap: a margin so large it would black out too much of the scene: clamped and flagged.

#include <cstdint>
#include <deque>

#include "core/error.h"
#include "projector/motion.h"

namespace studio::projector {

struct MarginOptions {
  double floor_m = 0.01;
  double cap_m = 0.20;
  bool prediction = true;
  double velocity_uncertainty_mps = 0.05;  // sigma_v
  double head_disagreement_mps = 0.5;
  double max_acceleration_mps2 = 15.0;  // physical bound on the actor's acceleration (above)
  bool worst_case_acceleration = true;  // a = max_acceleration_mps2 whatever the estimate
  Expected<void> validate() const;
};

struct Margin {
  double margin_m = 0;  // what to grow the mask by
  double floor_m = 0;
  double motion_m = 0;  // the motion term before clamping
  double latency_s = 0;
  double speed_mps = 0;               // v (no-prediction term)
  double acceleration_mps2 = 0;       // a (prediction term), after the bound
  double velocity_age_s = 0;          // the prediction's velocity: this long before the capture
  bool acceleration_bounded = false;  // the estimate was above max_acceleration_mps2
  bool predicted = false;             // the mesh is to be moved forward by latency_s
  bool capped = false;
};

// latency_s: L; head_speed_mps: |head velocity| of the actor (0 if unknown); motion: the latest
// mesh motion (nullptr if unknown); velocity_age_s: how long before the mesh's capture the
// prediction's velocity stands for (above; negative: motion->dt_s / 2, the mesh's own fit).
// Errors: invalid options, negative or non-finite inputs.
Expected<Margin> security_margin(const MarginOptions& options, double latency_s,
                                 double head_speed_mps, const MeshMotion* motion,
                                 double velocity_age_s = -1);

// A sliding window of measured latencies (seconds) and its quantile.
class LatencyWindow {
 public:
  explicit LatencyWindow(size_t capacity = 100, double quantile = 0.95)
      : capacity_(capacity), quantile_(quantile) {}
  // capture_ns: the mesh's capture time; shown_ns: when the frame using it was shown (same clock).
  // A negative or absurd (> 10 s) latency is rejected (false) and not kept.
  bool add(int64_t capture_ns, int64_t shown_ns);
  bool empty() const { return samples_.empty(); }
  size_t size() const { return samples_.size(); }
  // The configured quantile of the window (nearest rank), 0 when empty.
  double latency_s() const;

 private:
  size_t capacity_;
  double quantile_;
  std::deque<double> samples_;
};

}  // namespace studio::projector

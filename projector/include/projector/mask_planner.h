#pragma once
// The projector's actor mask, frame by frame (TCSVT 2004 §V-D, and beyond it): keeps the latest
// mesh of every actor and its motion, and for each projector frame returns the meshes to draw
// black: each moved forward by its predicted motion to the moment the frame is shown and grown
// by the computed security margin (projector/mask_margin.h, motion.h, mask_geometry.h).
//
// Latency L for the margin, per actor and frame: the motion-to-photon latency of this frame's
// mesh, i.e. its age when the frame is shown = (display_ns - capture_ns), known at plan time up
// to how late the frame really is shown, plus the configured quantile of that lateness measured
// on the frames shown so far (shown_ns - planned display_ns, 0 when early; recorded by shown()).
// Before any frame was shown: max(age, initial_latency_s). So a mesh that spent long in the
// pipeline — or a frame drawn long after its mesh (the hull stalled) — is covered for the time
// it has really been moving, and a slow earlier mesh does not inflate the margin of a fresh one.
// latency_s() reports the quantile of the measured motion-to-photon latencies (capture_ns ->
// shown) for the status. Prediction horizon per mesh: its age when the frame is shown,
// display_ns - capture_ns. One margin for all actors: the largest of theirs (head speed of an
// actor from set_head_speed(), 0 when unknown).
//
// Cost: set_mesh() does the per-mesh work once — the motion estimate and the mask mesh's
// simplification (mask_geometry.h simplify_for_mask; the outline form keeps the mesh whole), by
// default on two threads at once (MaskPlannerOptions::parallel_mesh_work) — and times both
// (last_mesh_cost()); plan() per frame only moves the mask mesh forward and grows it.
//
// Late latching (issues 15/20: the mesh off the long path; the projector node's default,
// ProjectorNodeOptions::late_latch): latch_mesh() takes a new mesh with only what its first
// frame needs — the simplification and, per vertex the mask uses, the velocity of the PREVIOUS
// fit looked up in its field (projector/velocity_field.h, O(1) per vertex) — and leaves its own
// motion fit pending; fit_pending(), called after that frame, fits it against the previous mesh
// (MotionTracker, as set_mesh) and builds the field the next mesh's latch reads. Frames planned
// before the fit move the mesh by the latched velocities and their margin counts the velocity's
// age (mask_margin.h: (capture - previous capture) + previous dt / 2 instead of dt / 2); frames
// after the fit use the mesh's own motion, as set_mesh's. A latched mesh whose field is older
// than MotionOptions::max_dt_s (or with no field yet) is not predicted: the no-prediction margin
// with the actor's last known speed, as a mesh after a gap. The fit may also run elsewhere
// (FitWorker, projector/fit_worker.h, on its own thread): apply_fit() installs it, and a fit that
// lands after a newer mesh was latched re-latches that mesh from its fresher field.
//
// A mesh without a motion estimate (the first after a gap longer than MotionOptions::max_dt_s,
// e.g. the hull stalled) is not taken as still: its no-prediction margin uses the actor's last
// known speed (the fastest region of its last estimate) when that exceeds its head's.
//
// Bad input is refused by set_mesh() (empty, malformed, capture time going backwards) and the
// previous mesh of that actor stays in use; the caller counts the refusal.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "projector/actor_mesh.h"
#include "projector/mask_geometry.h"
#include "projector/mask_margin.h"
#include "projector/motion.h"
#include "projector/motion_fit.h"
#include "projector/velocity_field.h"

namespace studio::projector {

struct MaskPlannerOptions {
  MarginOptions margin;
  MotionOptions motion;
  GrowOptions grow;
  std::size_t latency_window = 100;  // frames
  double latency_quantile = 0.95;
  double initial_latency_s = 0.04;
  // set_mesh() simplifies the mask mesh on a second thread while it fits the motion (wall time
  // per mesh: the longer stage, not the sum; the same results and CPU). false: one after the
  // other on the calling thread.
  bool parallel_mesh_work = true;
  Expected<void> validate() const;
};

struct MaskPlan {
  std::vector<ActorMesh> masks;        // predicted and grown, one per actor
  Margin margin;                       // the margin in use (the largest of the actors')
  std::int64_t newest_capture_ns = 0;  // of the newest mesh in the plan (0: none)
  std::uint64_t newest_frame = 0;
  std::int64_t display_ns = 0;  // the instant it was planned for
};

// Wall time of set_mesh()'s two stages, seconds (steady clock); in parallel, motion_s is the
// whole set_mesh's wait (the motion fit, then the join of the simplification).
struct MeshCost {
  double motion_s = 0;    // MotionTracker::update (latch_mesh: 0; fit_pending: its fits)
  double simplify_s = 0;  // simplify_for_mask
  double latch_s = 0;     // latch_mesh: the velocities looked up in the previous fit's field
  double field_s = 0;     // fit_pending: the velocity field built from the fit
};

class MaskPlanner {
 public:
  explicit MaskPlanner(MaskPlannerOptions options = {});

  // The latest mesh of an actor (frame: its studio frame). Errors: invalid mesh, capture time not
  // after the actor's previous mesh. The motion is estimated against that previous mesh.
  Expected<void> set_mesh(const std::string& actor_id, std::uint64_t frame, ActorMesh mesh);
  // Late latching (above): the mesh simplified and given the previous fit's velocities; its
  // own motion fit left for fit_pending(). Errors: those of set_mesh().
  Expected<void> latch_mesh(const std::string& actor_id, std::uint64_t frame, ActorMesh mesh);
  // Fits the motion of every latched mesh not fitted yet (MotionTracker::update against the
  // actor's previous mesh) and builds its velocity field. Returns the meshes tried (the first
  // mesh of an actor gives no motion yet); the cost
  // lands in last_mesh_cost().motion_s / field_s. A failed fit leaves the mesh unpredicted.
  int fit_pending();
  // Installs a fit computed elsewhere (FitWorker, projector/fit_worker.h; fit_pending() uses it
  // too). The current mesh's own fit (same capture time): as fit_pending() — the mesh predicted by
  // its own motion from now on, its field kept for the next latch. An older mesh's fit that
  // finished after a newer mesh was latched: its field replaces an older one and the current mesh,
  // while it has no fit of its own, is latched again from it (fresher velocities, a smaller age).
  // Anything else (an unknown actor, a newer or refused fit, a field no newer than the one held):
  // ignored.
  enum class Applied { ignored, own, field };
  Applied apply_fit(FitResult fit);
  void remove(const std::string& actor_id);
  void set_head_speed(const std::string& actor_id, double speed_mps);
  // Replaces the margin options for the next plans (a margin sweep: floor = cap = the margin
  // under test, prediction on or off). Errors: invalid options (the old ones stay).
  Expected<void> set_margin_options(const MarginOptions& margin);
  std::size_t actors() const { return actors_.size(); }
  // The cost of the last accepted set_mesh().
  const MeshCost& last_mesh_cost() const { return last_cost_; }

  // The masks for a frame to be shown at display_ns (CLOCK_REALTIME).
  Expected<MaskPlan> plan(std::int64_t display_ns) const;
  // The frame using `plan` was rendered at shown_ns: records its latency. False when rejected
  // (no mesh, or a latency that is negative or above 10 s).
  bool shown(const MaskPlan& plan, std::int64_t shown_ns);
  double latency_s() const;
  // The quantile of (shown - planned display), seconds (0 before any frame was shown).
  double overrun_s() const { return overruns_.empty() ? 0.0 : overruns_.latency_s(); }

 private:
  struct Actor {
    explicit Actor(MotionTracker t) : tracker(std::move(t)) {}
    ActorMesh mesh;
    MaskBase base;  // mesh, simplified for the mask (a subset of its vertices)
    std::uint64_t frame = 0;
    MotionTracker tracker;
    std::optional<MeshMotion> motion;
    std::vector<Eigen::Vector3f> fitted;  // motion's velocity per vertex of base.mesh
    double head_speed_mps = 0;
    double known_speed_mps = 0;  // the fastest region of the last motion estimated (kept)
    // Late latching: the mesh awaits its fit; the field of the last fit and that fit's motion
    // (for the margin's acceleration and speed); the velocities latched for the mesh (empty:
    // none, not predicted until fitted).
    bool pending = false;
    std::optional<VelocityField> field;
    std::optional<MeshMotion> field_motion;
    std::vector<Eigen::Vector3f> latched;
    double latched_age_s = 0;  // the latched velocity's age at the mesh's capture
  };
  // The actor a new mesh is for (created on its first mesh), once the mesh is valid and captured
  // after that actor's current one: the checks set_mesh() and latch_mesh() share.
  Expected<Actor*> accept(const std::string& actor_id, const ActorMesh& mesh);
  // The latched velocities of a's current mesh from a's field (none when the field is missing or
  // older than MotionOptions::max_dt_s).
  void relatch(Actor& a);
  MaskPlannerOptions options_;
  std::map<std::string, Actor> actors_;
  LatencyWindow latencies_;
  LatencyWindow overruns_;  // shown_ns - planned display_ns (>= 0), same window and quantile
  MeshCost last_cost_;
};

}  // namespace studio::projector

#pragma once
// One motion fit of late latching (projector/mask_planner.h): a mesh's motion against the last
// mesh its tracker fitted (MotionTracker::update, projector/motion.h) and the velocity field the
// next mesh's latch reads (projector/velocity_field.h), as one value that can cross threads.
// MaskPlanner::fit_pending() computes it on the render thread; FitWorker (fit_worker.h) on a
// thread of its own; MaskPlanner::apply_fit() installs it either way, so both forms give the
// same velocities for the same sequence of fitted meshes.

#include <cstdint>
#include <optional>
#include <string>

#include "projector/actor_mesh.h"
#include "projector/motion.h"
#include "projector/velocity_field.h"

namespace studio::projector {

struct FitResult {
  std::string actor;
  std::int64_t capture_ns = 0;         // of the mesh fitted
  std::optional<MeshMotion> motion;    // none: the actor's first mesh, after a gap, or refused
  std::optional<VelocityField> field;  // built from `motion` (none when that failed)
  std::string error;                   // the refusal, when the tracker refused the mesh
  double motion_s = 0;                 // wall time of the fit (MotionTracker::update)
  double field_s = 0;                  // wall time of the field's construction
};

// `mesh`'s motion from `tracker` (which keeps the mesh as its next target) and, when there is one,
// its velocity field with cells of field_cell_m (MotionOptions::region_size_m).
FitResult fit_motion(MotionTracker& tracker, const std::string& actor, const ActorMesh& mesh,
                     double field_cell_m);

}  // namespace studio::projector

#pragma once
// The projector node's samples: studio/actor/mesh in (validated by the reader: sizes, indices,
// finite) as the mask's mesh, and one rendered frame out as studio/projector/frame
// (idl/studio.idl, ProjectorFrame).

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "projector/actor_mesh.h"
#include "projector/mask_planner.h"
#include "projector_render/frame_renderer.h"
#include "studio.h"

namespace studio::projector {

ActorMesh mesh_of(const studio_ActorMesh& sample);

struct FrameInfo {
  std::string projector_id;
  const MaskPlan* plan = nullptr;  // nullptr: no mask planned
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  bool two_pass = false;
  std::uint64_t render_frame = 0;
  std::int64_t render_done_ns = 0;
};

// Fills every field of `f` from the frame and its read-back (blackout runs, thumbnail).
void fill_frame(const FrameInfo& info, const projector_render::Readback& rb,
                studio_ProjectorFrame& f);

}  // namespace studio::projector

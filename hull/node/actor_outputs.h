#pragma once
// What the hull service publishes for each frame it cuts (hull_node.h): per actor its segments
// (studio/actor/segments) and, with `mesh: true`, its mesh by segment marching cubes with the
// exact crossings when `refine: true` (studio/actor/mesh); the disposal of an actor gone; and
// with `projector_masks: true` every projector's actor mask by the viewpoint cut (eq. 7-8,
// hull/projector_mask.h; studio/projector/mask). Loop thread only.
#include <chrono>
#include <span>
#include <string>

#include "core/camera.h"
#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"
#include "hull_node.h"
#include "runtime/service_loop.h"

namespace studio::hull {

class ActorOutputs {
 public:
  using Duration = std::chrono::steady_clock::duration;
  // Where a frame's publishing time went (summed over its actors; hull_stages.h).
  struct Durations {
    Duration mesh{}, refine{}, publish{};
  };
  // The frame the outputs belong to.
  struct FrameId {
    uint64_t frame = 0;
    int64_t capture_ns = 0;
  };

  // Creates the outputs on `loop` (before it starts); `options` must outlive this.
  ActorOutputs(runtime::ServiceLoop& loop, const HullNodeOptions& options);

  void actor(const SegmentSet& set, const std::string& actor_id, FrameId frame,
             std::span<const View> views, const CutOptions& cut, Durations& d);
  void dispose(const std::string& actor_id);
  // Every projector's mask of this frame's views (a projector that fails is logged and skipped).
  void projector_masks(FrameId frame, std::span<const Camera> projectors,
                       std::span<const View> views, const CutOptions& cut);
  bool publishes_projector_masks() const { return projector_masks_ != nullptr; }

 private:
  const HullNodeOptions& options_;
  runtime::Output<studio_SegmentSet>* segs_ = nullptr;
  runtime::Output<studio_ActorMesh>* meshes_ = nullptr;
  runtime::Output<studio_ProjectorMask>* projector_masks_ = nullptr;
};

}  // namespace studio::hull

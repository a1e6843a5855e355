#pragma once
// The simulated studio's actor rendered through any rig (capture/sim), and the naive voxel carve
// used as the reference volume and as the benchmark's baseline (issue 18). Not part of the
// library.

#include <Eigen/Core>
#include <vector>

#include "sim/actor.h"
#include "core/camera.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"

namespace studio::hull::testing {

// The actor's true solid at `frame` (25 fps, the simulated studio's default) and its bounds.
sim::ActorBody sim_actor_body(const sim::Actor::Options& actor, int64_t frame);
void bounds(const sim::ActorBody& body, Eigen::Vector3d* lo, Eigen::Vector3d* hi);

struct SimFrame {
  std::vector<Camera> cameras;
  std::vector<Mask> truth;  // true masks (255 actor), decoded
  std::vector<RunMask> masks;
  std::vector<View> views() const;
};
// True masks of `cameras` (the simulated studio's renderer) at `frame`.
SimFrame render_sim(const sim::Actor::Options& actor, int64_t frame, std::vector<Camera> cameras);

// The naive voxel carve done well: projection matrices precomputed, voxel centres of an
// n x n x n lattice over the grid's box, a voxel rejected by the first camera that sees it
// outside its silhouette, the visibility policy (a camera sees a voxel in front of it whose
// centre falls in the image rectangle; at least `need` must), the same pixel lookup as the cut
// (pixel squares [x-0.5, x+0.5); decoded masks). One core.
class VoxelCarve {
 public:
  VoxelCarve(const std::vector<Camera>& cameras, const std::vector<Mask>& masks, int min_views);
  // Occupied voxels.
  std::size_t carve(const GridSpec& box, int n) const;
  bool keeps(const Eigen::Vector3d& x) const;

 private:
  std::vector<Eigen::Matrix<double, 3, 4>> P_;
  std::vector<const Mask*> masks_;
  int need_ = 0;
};

}  // namespace studio::hull::testing

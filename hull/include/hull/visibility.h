#pragma once
// How much of the reconstruction box the cameras cover under the visibility policy (issue 18;
// the policy itself: hull/silhouette_cut.h, CutOptions::min_views). A camera sees a point in
// front of it that projects into its image. The report depends only on the cameras and the box,
// not on the masks: a service computes it when its cameras or box change and reports it; a user
// reads it to see whether the box is looser than the rig (large unseen fractions) and how much
// of it min_views cuts regardless of the silhouettes.

#include <span>

#include "core/camera.h"
#include "core/error.h"
#include "hull/segment_set.h"

namespace studio::hull {

struct Coverage {
  int cameras = 0;
  int min_views = 0;           // resolved (kAllViews -> cameras)
  double unseen = 0;           // fraction of the box's volume no camera sees
  double below_min_views = 0;  // fraction seen by fewer than min_views cameras (cut by policy)
};

// Exact along every column of `grid` (the seen part of a line is one interval per camera; the
// count is swept over their end points), sampled across columns at the grid's resolution.
// Costs columns x cameras. Fails on an invalid grid or min_views.
Expected<Coverage> coverage(const GridSpec& grid, std::span<const Camera> cameras, int min_views);

}  // namespace studio::hull

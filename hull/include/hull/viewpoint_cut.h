#pragma once
// The viewpoint cut (TCSVT 2004 §IV-B, eq. 7-8): the line-segment hull with its lines laid along
// the lines of sight of a viewpoint (a camera or a projector, which is an inverse camera) instead
// of a regular grid. Each sampled pixel's ray from the viewpoint centre, clipped to the box, is
// cut by every silhouette exactly like a grid column, under the same visibility policy
// (options.cut.min_views, hull/silhouette_cut.h); the result is, per pixel, whether the
// actor covers it and the depth intervals along the ray — a mask for that viewpoint (the
// projector mask) without building a mesh. All rays pass through the viewpoint centre, so their
// images form a pencil through its epipole and the fast pencil path applies.

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/run_mask.h"
#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

struct ViewpointOptions {
  int step = 1;  // sample every step-th pixel in x and y (1..64)
  CutOptions cut;
  Expected<void> validate() const;
};

struct ViewpointCut {
  int width = 0, height = 0;  // samples: ceil(camera size / step)
  int step = 1;
  // Per sample (x + y * width): intervals of distance along the unit ray from the viewpoint
  // centre (metres); multiply by the ray's cosine with the optical axis for z-depth.
  std::vector<Interval> intervals;
  std::vector<uint32_t> start;
  RunMask coverage;  // samples with at least one interval, width x height

  std::span<const Interval> at(int x, int y) const {
    const std::size_t c = std::size_t(x) + std::size_t(y) * width;
    return {intervals.data() + start[c], intervals.data() + start[c + 1]};
  }
};

Expected<ViewpointCut> viewpoint_cut(const Camera& viewpoint, const Eigen::AlignedBox3d& box,
                                     std::span<const View> views,
                                     const ViewpointOptions& options = {});

}  // namespace studio::hull

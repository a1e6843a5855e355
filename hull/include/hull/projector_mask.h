#pragma once
// The actor mask of a projector by the viewpoint cut (TCSVT 2004 §IV-B eq. 7-8, §V-D): the
// alternative to drawing the actor mesh from the projector. The hull service has every camera's
// silhouette and calibration; for each projector it knows (an inverse camera) it cuts the rays
// of the projector's pixels (hull/viewpoint_cut.h, every `step`-th pixel in x and y) and
// publishes which projector pixels the actor covers, at the projector's full resolution.
//
// Contract: pixel (x, y) of the W x H result is set iff the sample nearest to it is covered,
// sample (sx, sy) being pixel (sx step, sy step): the block of pixels
// [sx step - step/2, sx step - step/2 + step) x [same in y] (integer division), clipped to the
// image. With step 1 the result is the viewpoint cut's coverage itself. The security margin
// (latency x speed) is the projector's to add (projector/mask_margin.h), not the hull's.

#include <Eigen/Geometry>
#include <span>

#include "core/camera.h"
#include "core/error.h"
#include "core/run_mask.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

struct ProjectorMaskOptions {
  int step = 2;  // 1..64
  CutOptions cut;
  Expected<void> validate() const;
};

// Errors: invalid options, an invalid projector camera, those of viewpoint_cut().
Expected<RunMask> projector_mask(const Camera& projector, const Eigen::AlignedBox3d& box,
                                 std::span<const View> views,
                                 const ProjectorMaskOptions& options = {});

// The block expansion of the contract above: a coverage of ceil(W / step) x ceil(H / step)
// samples to a W x H mask. Exposed for tests.
RunMask expand_samples(const RunMask& samples, int step, int width, int height);

}  // namespace studio::hull

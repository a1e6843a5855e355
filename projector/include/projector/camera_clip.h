#pragma once
// The projector seen as a camera in OpenGL clip space: what the actor mask is drawn with (TCSVT
// 2004 §V-D: the actor mesh rendered black "from the projector's point of view"). A world point
// lands on exactly the projector pixel core/camera.h's ideal (distortion-free) projection gives,
// with the pixel/NDC conventions of projector/projector_view.h (pixel (0, 0) = centre of the
// top-left pixel, NDC x = (2u + 1) / W - 1, y = 1 - (2v + 1) / H). Depth: NDC z from -1 at
// `near` to 1 at `far` metres along the projector's optical axis; w = that depth.
//
// With K = [fx s cx; 0 fy cy; 0 0 1] and x_cam = cam_from_world x (z forward, y down):
//   clip = [2fx/W, 2s/W, (2cx+1)/W - 1, 0;  0, -2fy/H, 1 - (2cy+1)/H, 0;
//           0, 0, (f+n)/(f-n), -2fn/(f-n);  0, 0, 1, 0] * [x_cam; 1]

#include <Eigen/Core>

#include "core/camera.h"

namespace studio::projector {

Eigen::Matrix4d clip_from_world(const Camera& projector, double near_m = 0.05,
                                double far_m = 100.0);

}  // namespace studio::projector

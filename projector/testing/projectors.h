#pragma once
// Projectors of a small studio for tests and benchmarks: 1920x1080, in front of their screens
// (back wall, left wall, a tilted free-standing screen), aimed at the screen's centre with lens
// shift and a focal length that fits the screen into the image.

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "core/rig.h"

namespace studio::projector::testing {

Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll);
Projector make_projector(const std::string& id, const std::array<Eigen::Vector3d, 4>& corners,
                         const Eigen::Vector3d& offset, double roll);
// back, left, tilted.
std::vector<Projector> studio_projectors();
// The back-wall projector as "proj0" at half resolution (960x540), so llvmpipe keeps up in the
// node tests on a loaded machine (the intrinsics halved about the pixel-centre convention).
Projector half_back_projector();

}  // namespace studio::projector::testing

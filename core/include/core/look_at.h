#pragma once
// Placing a camera by look-at: the one copy used by the simulated studio (sim/), synthetic
// calibration scenes (calibrate/) and the tests (tests/support).

#include <Eigen/Core>

#include "core/transform.h"

namespace studio {

// cam_from_world of a camera at `centre` whose optical axis (camera +z) points at `target`, with
// the world direction `up` appearing as up in the image (camera -y, since image v grows
// downwards; core/camera.h conventions): camera y is the component of -up perpendicular to the
// optical axis, camera x = y × z (right-handed). When the optical axis is within ~2.6° of ±up
// (|cos| > 0.999), image y points to world +z instead (+x when `up` is itself close to z): the
// overhead camera of the simulated studio. `centre` must differ from `target` (std::invalid_argument).
Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());

}  // namespace studio

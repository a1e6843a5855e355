#include "core/look_at.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace studio {

Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d view = target - centre;
  if (!(view.norm() > 0) || !(up.norm() > 0) || !view.allFinite() || !up.allFinite()) {
    throw std::invalid_argument("look_at: centre equals target, or up is zero or not finite");
  }
  const Eigen::Vector3d z = view.normalized();
  Eigen::Vector3d down = -up.normalized();
  if (std::abs(z.dot(down)) > 0.999) {
    down = std::abs(up.normalized().z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  }
  const Eigen::Vector3d x = down.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d cam_from_world_R;
  cam_from_world_R.row(0) = x;
  cam_from_world_R.row(1) = y;
  cam_from_world_R.row(2) = z;
  return Rigid3(cam_from_world_R, -(cam_from_world_R * centre));
}

}  // namespace studio

#include "testing/tilted_rig.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "support/cameras.h"
#include "testing/synthetic.h"

namespace studio::hull::testing {

std::vector<Camera> tilted_rig(const Eigen::Vector3d& centre, const TiltedRigOptions& o) {
  std::vector<Camera> out;
  const double deg = M_PI / 180;
  for (int k = 0; k < o.count; ++k) {
    const int level = k % 4;
    const double az = (360.0 * k / o.count + 5 * std::sin(1.7 * k)) * deg;
    const double height = 0.9 + 0.8 * level;
    const double dist = 3.3 + 0.35 * ((k * 7) % 4);
    const double tilt = (10 + 8 * level + 2 * ((k / 4) % 4)) * deg;  // 10 .. 40
    const double roll = (k % 3 == 1 ? 6 : k % 5 == 2 ? -9 : 0) * deg;
    const Eigen::Vector3d c(centre.x() + dist * std::sin(az), height,
                            centre.z() + dist * std::cos(az));
    const Eigen::Vector3d horizontal(-std::sin(az), 0, -std::cos(az));
    const Eigen::Vector3d axis =
        std::cos(tilt) * horizontal - std::sin(tilt) * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d up = Eigen::AngleAxisd(roll, axis) * Eigen::Vector3d::UnitY();
    out.push_back(
        support::look_at_camera("cam" + std::to_string(k), c, c + axis, up, o.width, o.height, o.focal_px));
  }
  return out;
}

GridSpec loose_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double factor, int n) {
  const Eigen::Vector3d size = hi - lo;
  GridSpec g;
  g.box_min = lo - 0.05 * size;
  g.box_max = g.box_min + factor * size;
  g.axis = Axis::y;
  g.cells_u = g.cells_v = n;
  return g;
}

GridSpec tight_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin, int n) {
  GridSpec g;
  g.box_min = lo - Eigen::Vector3d::Constant(margin);
  g.box_max = hi + Eigen::Vector3d::Constant(margin);
  g.axis = Axis::y;
  g.cells_u = g.cells_v = n;
  return g;
}

}  // namespace studio::hull::testing

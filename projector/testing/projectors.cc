#include "testing/projectors.h"

#include <algorithm>
#include <cmath>

namespace studio::projector::testing {

Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam;
  world_from_cam << x, y, z;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                            world_from_cam.transpose();
  return Rigid3(R, -R * centre);
}

// A 1920x1080 projector in front of its screen, above and to the side of the acting area, aimed at
// the screen's centre, with lens shift and a focal length that fits the screen into the image.
Projector make_projector(const std::string& id, const std::array<Eigen::Vector3d, 4>& corners,
                         const Eigen::Vector3d& offset, double roll) {
  Projector p;
  p.screen = corners;
  Camera& c = p.camera;
  c.id = id;
  c.width = 1920;
  c.height = 1080;
  const Eigen::Vector3d centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  const Eigen::Vector3d normal =
      (corners[1] - corners[0]).cross(corners[3] - corners[0]).normalized();
  const Eigen::Vector3d position = centre + normal * offset.z() +
                                   offset.x() * (corners[1] - corners[0]).normalized() +
                                   offset.y() * Eigen::Vector3d::UnitY();
  c.cam_from_world = look_at(position, centre, roll);
  double extent_x = 0, extent_y = 0;
  for (const auto& k : corners) {
    const Eigen::Vector3d x = c.cam_from_world * k;
    extent_x = std::max(extent_x, std::abs(x.x() / x.z()));
    extent_y = std::max(extent_y, std::abs(x.y() / x.z()));
  }
  const double f = 0.95 * std::min(960 / extent_x, 540 / extent_y);
  c.intrinsics = {f, f * 1.001, 959.5 + 12, 539.5 - 20, 0};
  return p;
}

std::vector<Projector> studio_projectors() {
  std::vector<Projector> out;
  // Back wall, facing +z.
  out.push_back(make_projector("back",
                               {Eigen::Vector3d(-2, 0, -2), Eigen::Vector3d(2, 0, -2),
                                Eigen::Vector3d(2, 2.5, -2), Eigen::Vector3d(-2, 2.5, -2)},
                               {0.4, 1.2, 4.0}, 0.02));
  // Left wall, facing +x.
  out.push_back(make_projector("left",
                               {Eigen::Vector3d(-2.5, 0, 1), Eigen::Vector3d(-2.5, 0, -1.5),
                                Eigen::Vector3d(-2.5, 2.4, -1.5), Eigen::Vector3d(-2.5, 2.4, 1)},
                               {-0.3, 1.0, 3.5}, -0.03));
  // A tilted free-standing screen, facing roughly +x +z.
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d o(1.5, 0.2, -1.2);
  out.push_back(
      make_projector("tilted",
                     {o, o + r * Eigen::Vector3d(1.8, 0, 0), o + r * Eigen::Vector3d(1.8, 1.6, 0),
                      o + r * Eigen::Vector3d(0, 1.6, 0)},
                     {0.2, -0.4, 3.0}, 0.05));
  return out;
}

Projector half_back_projector() {
  Projector p = studio_projectors()[0];
  Camera& c = p.camera;
  c.id = "proj0";
  c.width = 960;
  c.height = 540;
  c.intrinsics.fx /= 2;
  c.intrinsics.fy /= 2;
  c.intrinsics.cx = (c.intrinsics.cx + 0.5) / 2 - 0.5;
  c.intrinsics.cy = (c.intrinsics.cy + 0.5) / 2 - 0.5;
  return p;
}

}  // namespace studio::projector::testing

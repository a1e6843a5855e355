#include "support/cameras.h"

#include <cmath>
#include <numbers>

#include "core/look_at.h"
#include "core/rig.h"
#include "yaml_io/rig_yaml.h"

namespace studio::support {

Camera look_at_camera(const std::string& id, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& target, const Eigen::Vector3d& up, int width,
                      int height, double focal_px, const Distortion& distortion) {
  Camera c;
  c.id = id;
  c.width = width;
  c.height = height;
  c.intrinsics.fx = c.intrinsics.fy = focal_px;
  c.intrinsics.cx = 0.5 * (width - 1);
  c.intrinsics.cy = 0.5 * (height - 1);
  c.distortion = distortion;
  c.cam_from_world = look_at(centre, target, up);
  return c;
}

std::vector<Camera> camera_ring(int n, int width, int height, double radius, double height_m,
                                const Eigen::Vector3d& target, double focal_px,
                                const Distortion& distortion) {
  std::vector<Camera> out;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * (k + 0.25) / n;
    const Eigen::Vector3d c(target.x() + radius * std::cos(a), height_m,
                            target.z() + radius * std::sin(a));
    out.push_back(look_at_camera("cam" + std::to_string(k), c, target, Eigen::Vector3d::UnitY(),
                                 width, height, focal_px, distortion));
  }
  return out;
}

Expected<void> write_rig_yaml(const std::vector<Camera>& cameras, const std::filesystem::path& path) {
  Rig rig;
  rig.cameras = cameras;
  return yaml::write_rig(rig, path.string());
}

}  // namespace studio::support

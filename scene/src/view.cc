#include "scene/view.h"

#include <cmath>

namespace studio::scene {

Eigen::Matrix4d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& at,
                        const Eigen::Vector3d& up) {
  const Eigen::Vector3d f = (at - eye).normalized();  // forward = camera -z
  Eigen::Vector3d s = f.cross(up);
  if (s.norm() < 1e-9) s = f.cross(Eigen::Vector3d::UnitZ());  // looking straight up or down
  s.normalize();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.row(0).head<3>() = s;
  m.row(1).head<3>() = u;
  m.row(2).head<3>() = -f;
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Eigen::Matrix4d perspective(double fov_y, double aspect, double n, double f) {
  const double t = 1.0 / std::tan(fov_y / 2);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (f + n) / (n - f);
  m(2, 3) = 2 * f * n / (n - f);
  m(3, 2) = -1;
  return m;
}

Eigen::Vector2d project_to_pixel(const Eigen::Matrix4d& clip_from_world, const Eigen::Vector3d& x,
                                 int width, int height, bool* depth_ok) {
  const Eigen::Vector4d c = clip_from_world * x.homogeneous();
  if (depth_ok) *depth_ok = c[3] > 0;
  const double nx = c[0] / c[3], ny = c[1] / c[3];
  return {(nx + 1) * 0.5 * width, (1 - ny) * 0.5 * height};
}

}  // namespace studio::scene

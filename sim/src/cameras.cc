// Virtual camera rigs for the simulated studio (sim/cameras.h).
#include "sim/cameras.h"

#include <cmath>
#include <numbers>

#include "message.h"

namespace studio::sim {

Expected<void> RingOptions::validate() const {
  if (count < 1 || count > 64) return fail(detail::cat("ring camera count ", count, " outside [1, 64]"));
  if (width < 16 || height < 16 || width > 8192 || height > 8192) {
    return fail(detail::cat("ring camera size ", width, "x", height, " outside [16, 8192]"));
  }
  if (!(radius > 1.5 && radius < 20)) return fail(detail::cat("ring radius ", radius, " m outside (1.5, 20)"));
  if (!(focal_px > 1)) return fail(detail::cat("ring focal length ", focal_px, " px must be > 1"));
  if (!(height_m > 0 && overhead_height > 3)) {
    return fail("ring camera height must be > 0 and the overhead camera above 3 m");
  }
  return {};
}

Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  Eigen::Vector3d down(0, -1, 0);
  if (std::abs(z.dot(down)) > 0.999) down = Eigen::Vector3d(0, 0, 1);
  const Eigen::Vector3d x = down.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  return Rigid3(R, -(R * centre));
}

std::vector<Camera> ring_cameras(const RingOptions& o) {
  if (auto ok = o.validate(); !ok) throw std::invalid_argument(ok.error().message);
  std::vector<Camera> cameras;
  const int ring = o.overhead ? o.count - 1 : o.count;
  for (int i = 0; i < o.count; ++i) {
    Camera c;
    c.id = detail::cat("cam", i);
    c.width = o.width;
    c.height = o.height;
    c.intrinsics.fx = c.intrinsics.fy = o.focal_px;
    c.intrinsics.cx = (o.width - 1) / 2.0;
    c.intrinsics.cy = (o.height - 1) / 2.0;
    if (i < ring) {
      const double az = (o.first_azimuth_deg + 360.0 * i / ring) * std::numbers::pi / 180.0;
      const Eigen::Vector3d centre(o.radius * std::sin(az), o.height_m, o.radius * std::cos(az));
      c.cam_from_world = look_at(centre, Eigen::Vector3d(0, o.look_at_y, 0));
    } else {
      c.cam_from_world = look_at(Eigen::Vector3d(0, o.overhead_height, 0), Eigen::Vector3d::Zero());
    }
    cameras.push_back(c);
  }
  return cameras;
}

}  // namespace studio::sim

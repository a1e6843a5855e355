#include "core/look_at.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "core/camera.h"

namespace studio {
namespace {

Camera pinhole(const Rigid3& cam_from_world) {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.intrinsics = {.fx = 500, .fy = 500, .cx = 319.5, .cy = 239.5, .skew = 0};
  c.cam_from_world = cam_from_world;
  return c;
}

TEST(LookAt, TargetOnTheAxisUpIsUpAndRotationIsProper) {
  const Eigen::Vector3d centre(3, 2, -1), target(0, 1, 0.5);
  const Rigid3 cam_from_world = look_at(centre, target);
  EXPECT_NEAR(cam_from_world.R().determinant(), 1, 1e-12);
  EXPECT_NEAR(((cam_from_world * centre)).norm(), 0, 1e-12);
  const Camera c = pinhole(cam_from_world);
  Eigen::Vector2d px, above, right;
  ASSERT_TRUE(c.project(target, &px));
  EXPECT_NEAR((px - Eigen::Vector2d(319.5, 239.5)).norm(), 0, 1e-9);
  ASSERT_TRUE(c.project(target + Eigen::Vector3d(0, 0.1, 0), &above));
  EXPECT_LT(above.y(), px.y());            // world up is image up (v decreases)
  EXPECT_NEAR(above.x(), px.x(), 1e-9);    // and stays on the vertical through the target
  // Camera x is horizontal (no roll): a horizontal step sideways keeps v.
  const Eigen::Vector3d side = (target - centre).cross(Eigen::Vector3d::UnitY()).normalized();
  ASSERT_TRUE(c.project(target + 0.1 * side, &right));
  EXPECT_NEAR(right.y(), px.y(), 1e-9);
  EXPECT_GT(right.x(), px.x());
}

TEST(LookAt, GivenUpAndStraightDownFallback) {
  // up = +z: world +z appears up in the image.
  const Camera c = pinhole(look_at({0, 6, 0}, {0, 1, 0}, Eigen::Vector3d::UnitZ()));
  Eigen::Vector2d px, towards_z;
  ASSERT_TRUE(c.project({0, 1, 0}, &px));
  ASSERT_TRUE(c.project({0, 1, 0.2}, &towards_z));
  EXPECT_LT(towards_z.y(), px.y());
  // Looking straight down with y up: image y (down) points to world +z.
  const Rigid3 overhead = look_at({0, 5, 0}, Eigen::Vector3d::Zero());
  EXPECT_NEAR((overhead.R().row(1).transpose() - Eigen::Vector3d::UnitZ()).norm(), 0, 1e-12);
  EXPECT_NEAR(overhead.R().determinant(), 1, 1e-12);
}

TEST(LookAt, CentreAtTargetIsRefused) {
  EXPECT_THROW(look_at({1, 1, 1}, {1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(look_at({1, 1, 1}, {0, 0, 0}, Eigen::Vector3d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace studio

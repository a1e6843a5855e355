// The shared test helpers: ring cameras see their target at the principal point with y up, the
// rig.yaml they write reads back, and IoU counts pixels as documented.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "support/cameras.h"
#include "support/masks.h"
#include "yaml_io/rig_yaml.h"

namespace studio::support {
namespace {

TEST(Support, RingCamerasLookAtTheTarget) {
  const Eigen::Vector3d target(0.2, 1, -0.3);
  const auto ring = camera_ring(5, 320, 240, 4.0, 1.6, target, 300);
  ASSERT_EQ(ring.size(), 5u);
  for (const Camera& c : ring) {
    Eigen::Vector2d px, above;
    ASSERT_TRUE(c.project(target, &px));
    EXPECT_NEAR((px - Eigen::Vector2d(159.5, 119.5)).norm(), 0, 1e-9) << c.id;
    ASSERT_TRUE(c.project(target + Eigen::Vector3d(0, 0.2, 0), &above));
    EXPECT_LT(above.y(), px.y());
    const Eigen::Vector3d d = c.centre_in_world() - target;
    EXPECT_NEAR(std::hypot(d.x(), d.z()), 4.0, 1e-9);
    EXPECT_NEAR(c.centre_in_world().y(), 1.6, 1e-9);
  }
  EXPECT_EQ(ring[4].id, "cam4");
}

TEST(Support, RigYamlOfCamerasReadsBack) {
  const auto ring = camera_ring(3, 320, 240, 4.0, 1.6, {0, 1, 0}, 300);
  const auto path = std::filesystem::path(::testing::TempDir()) / "support_rig.yaml";
  ASSERT_TRUE(write_rig_yaml(ring, path));
  auto rig = yaml::read_rig(path.string());
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 3u);
  EXPECT_NEAR((rig->cameras[2].projection_matrix() - ring[2].projection_matrix()).norm(), 0, 1e-9);
  EXPECT_FALSE(write_rig_yaml(ring, "/nonexistent/dir/rig.yaml"));
}

TEST(Support, IouOfMasksAndRunMasks) {
  Mask a(10, 4, 0), b(10, 4, 0);
  for (int x = 0; x < 6; ++x) a(x, 1) = 255;  // 6 pixels
  for (int x = 3; x < 9; ++x) b(x, 1) = 1;    // 6 pixels, 3 shared
  EXPECT_DOUBLE_EQ(iou(a, b), 3.0 / 9.0);
  EXPECT_DOUBLE_EQ(iou(RunMask::from_mask(a.view()), RunMask::from_mask(b.view())), 3.0 / 9.0);
  EXPECT_DOUBLE_EQ(iou(Mask(10, 4, 0), Mask(10, 4, 0)), 1.0);
  EXPECT_THROW(iou(a, Mask(9, 4, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace studio::support

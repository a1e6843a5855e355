// RigBalance (preview/rig_balance.h): what it refuses and when it restarts. Its estimate against
// the simulated studio's truth: preview_quality_test (in process) and preview_studio_test (the
// running studio).
#include "preview/rig_balance.h"

#include <gtest/gtest.h>

namespace studio::preview {
namespace {

Camera camera(const std::string& id) {
  Camera c;
  c.id = id;
  c.width = 8;
  c.height = 6;
  c.intrinsics.fx = c.intrinsics.fy = 10;
  return c;
}

TEST(RigBalance, RefusesViewsOutsideTheRigAndRestartsWhenTheRigChanges) {
  std::map<std::string, Camera> rig{{"cam0", camera("cam0")}, {"cam1", camera("cam1")}};
  std::vector<Rgb8> pixels(8 * 6, Rgb8{100, 100, 100});
  const ImageView<const Rgb8> image(pixels.data(), 8, 6);
  const RunMask mask = RunMask::from_mask(Mask(8, 6).view());
  RigBalance b;
  const scene::ActorMesh mesh;
  // Positive control: two calibrated cameras' views of an empty mesh pool a frame (no samples).
  ASSERT_TRUE(b.add(rig, mesh, {{"cam0", image, &mask}, {"cam1", image, &mask}}).has_value());
  EXPECT_EQ(b.balance().frames, 1);
  EXPECT_EQ(b.cameras(), (std::vector<std::string>{"cam0", "cam1"}));
  auto outside = b.add(rig, mesh, {{"cam9", image, &mask}});
  ASSERT_FALSE(outside);
  EXPECT_NE(outside.error().message.find("cam9"), std::string::npos);
  EXPECT_FALSE(b.add(rig, mesh, {{"cam0", image, nullptr}}));
  const ImageView<const Rgb8> small(pixels.data(), 4, 6);
  EXPECT_FALSE(b.add(rig, mesh, {{"cam0", small, &mask}, {"cam1", image, &mask}}));
  EXPECT_EQ(b.balance().frames, 1);  // nothing pooled by the refused frames
  ASSERT_TRUE(b.add(rig, mesh, {}).has_value());
  EXPECT_EQ(b.balance().frames, 2);
  // A camera joins: the pooling restarts over the new rig.
  rig.emplace("cam2", camera("cam2"));
  ASSERT_TRUE(b.add(rig, mesh, {}).has_value());
  EXPECT_EQ(b.balance().frames, 1);
  EXPECT_EQ(b.cameras().size(), 3u);
  EXPECT_EQ(b.gains("cam2"), Eigen::Vector3f::Ones());
  EXPECT_EQ(b.gains("unknown"), Eigen::Vector3f::Ones());
}

// Applied beyond the tolerance, kept until every camera is within half of it.
TEST(RigBalance, AppliesBeyondTheToleranceAndKeepsItUntilWithinHalf) {
  auto rig = [](float off) {
    return std::vector<Eigen::Vector3f>{Eigen::Vector3f(1 + off, 1, 1), Eigen::Vector3f::Ones()};
  };
  EXPECT_FALSE(balance_applies(rig(0.025f), 0.03, false));
  EXPECT_TRUE(balance_applies(rig(0.035f), 0.03, false));
  EXPECT_TRUE(balance_applies(rig(-0.035f), 0.03, false));
  EXPECT_TRUE(balance_applies(rig(0.025f), 0.03, true));  // drifting back: still balanced
  EXPECT_TRUE(balance_applies(rig(0.016f), 0.03, true));
  EXPECT_FALSE(balance_applies(rig(0.014f), 0.03, true));  // within half: released
  EXPECT_FALSE(balance_applies({}, 0.03, true));
}

TEST(RigBalance, CountsTheLinkedCamerasOfEverySet) {
  offline::ColourBalance b;
  EXPECT_EQ(linked_cameras(b), 0);
  b.linked_set = {0, 0, -1, 3, 3, -1};  // two sets, two cameras linked to none
  EXPECT_EQ(linked_cameras(b), 4);
}

}  // namespace
}  // namespace studio::preview

// Matching the cameras' colours at their controls (preview/camera_match.h).
#include "preview/camera_match.h"

#include <gtest/gtest.h>

#include <cmath>

namespace studio::preview {
namespace {

CameraControls camera(const std::string& id, double gain_db = 0, bool ratios = true) {
  CameraControls c;
  c.camera = id;
  c.gain_db = ControlValue{gain_db, 0, 24};
  if (ratios) c.ratio_red = c.ratio_blue = ControlValue{1, 0.25, 4};
  return c;
}

// The factor per channel the plan's changes apply to `c`'s colours.
Eigen::Vector3d applied(const CameraMatch& m, const CameraControls& c) {
  Eigen::Vector3d f = Eigen::Vector3d::Ones();
  for (const ControlChange& x : m.changes) {
    if (x.camera != c.camera) continue;
    if (x.feature == "Gain") f *= std::pow(10.0, (x.to - x.from) / 20);
    if (x.feature == "BalanceRatioRed") f.x() *= x.to / x.from;
    if (x.feature == "BalanceRatioBlue") f.z() *= x.to / x.from;
  }
  return f;
}

TEST(CameraMatch, BringsEveryCameraToTheRigWithoutDarkeningACameraAtItsLowestGain) {
  // cam1 is a quarter too bright and at 0 dB (its lowest gain): the others are brightened to it.
  const std::vector<CameraControls> rig = {camera("cam0"), camera("cam1"), camera("cam2", 3)};
  const std::map<std::string, Eigen::Vector3f> estimate = {
      {"cam0", {1, 1, 1}}, {"cam1", {0.8f, 0.8f, 0.8f}}, {"cam2", {1.1f, 1.0f, 0.9f}}};
  auto m = plan_camera_match(estimate, rig);
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_NEAR(m->level_db, -20 * std::log10(0.8), 1e-6);
  // Every camera ends at its estimate times one common factor: the cameras agree.
  for (const CameraControls& c : rig) {
    const Eigen::Vector3d ratio =
        applied(*m, c).array() / estimate.at(c.camera).cast<double>().array();
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(ratio[ch], 1.25, 1e-5) << c.camera << " " << ch;
    EXPECT_TRUE(m->left.at(c.camera).isApprox(Eigen::Vector3f::Ones(), 1e-5f)) << c.camera;
  }
  for (const ControlChange& x : m->changes) {
    EXPECT_NE(x.camera, "cam1");  // nothing to change: it is the reference now
    if (x.feature == "Gain") {
      EXPECT_GE(x.to, 0);
    }
  }
  EXPECT_EQ(m->changes.size(), 4u);  // cam0 Gain; cam2 Gain, red, blue
}

TEST(CameraMatch, ACameraWithGammaTakesTheFactorToItsExponent) {
  // cam1 applies Gamma 0.45 after its Gain and white balance (delivered = sensor^0.45): a
  // factor f on its delivered values is f^(1 / 0.45) on the sensor's.
  CameraControls gamma = camera("cam1");
  gamma.exponent = 1 / 0.45;
  const std::map<std::string, Eigen::Vector3f> estimate = {{"cam0", {1, 1, 1}},
                                                           {"cam1", {1.1f, 1.05f, 0.95f}}};
  auto m = plan_camera_match(estimate, {camera("cam0"), gamma});
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_NEAR(m->level_db, 0, 1e-9);  // both can go where they must at level 0
  // On the delivered values: the control factors to the power 0.45 give the estimate.
  const Eigen::Vector3d delivered = applied(*m, gamma).array().pow(0.45);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(delivered[ch], estimate.at("cam1")[ch], 1e-5);
  EXPECT_TRUE(m->left.at("cam1").isApprox(Eigen::Vector3f::Ones(), 1e-5f));
  for (const ControlChange& x : m->changes) {
    if (x.feature == "Gain") {
      EXPECT_NEAR(x.to, 20 / 0.45 * std::log10(1.05), 1e-6);
    }
  }
  gamma.exponent = 0;
  EXPECT_FALSE(plan_camera_match(estimate, {gamma}));
}

TEST(CameraMatch, ReportsWhatTheControlsCannotTake) {
  // cam0 at its highest gain must brighten by 2 dB; cam1 has no controls but Gain; cam2 none.
  CameraControls top = camera("cam0", 24);
  CameraControls gain_only = camera("cam1", 10, false);
  CameraControls none;
  none.camera = "cam2";
  const std::map<std::string, Eigen::Vector3f> estimate = {
      {"cam0", Eigen::Vector3f::Constant(float(std::pow(10.0, 2.0 / 20)))},
      {"cam1", {1.1f, 1.0f, 1.0f}},
      {"cam2", {1.0f, 1.0f, 0.9f}}};
  auto m = plan_camera_match(estimate, {top, gain_only, none});
  ASSERT_TRUE(m) << m.error().message;
  // cam0 cannot go up: the level k = -2 dB keeps it where it is and takes the rest down.
  EXPECT_NEAR(m->level_db, -2, 1e-6);
  EXPECT_TRUE(m->left.at("cam0").isApprox(Eigen::Vector3f::Ones(), 1e-5f));
  // cam1: its gain goes down 2 dB (the level), its red is left to the preview's balance.
  EXPECT_NEAR(m->left.at("cam1").x(), 1.1f, 1e-5);
  EXPECT_NEAR(m->left.at("cam1").y(), 1.0f, 1e-5);
  // cam2 has no controls: all of it is left, at the rig's new level.
  const float k = float(std::pow(10.0, -2.0 / 20));
  EXPECT_NEAR(m->left.at("cam2").z(), 0.9f * k, 1e-5);
  EXPECT_NEAR(m->left.at("cam2").x(), k, 1e-5);

  // Conflicting bounds: both cameras at the ends of their ranges, both wanting outwards.
  auto both = plan_camera_match(
      {{"a", Eigen::Vector3f::Constant(2.0f)}, {"b", Eigen::Vector3f::Constant(0.5f)}},
      {camera("a", 24), camera("b", 0)});
  ASSERT_TRUE(both);
  for (const ControlChange& x : both->changes) {
    EXPECT_GE(x.to, 0);
    EXPECT_LE(x.to, 24);
  }
  EXPECT_GT(both->left.at("a").y() / both->left.at("b").y(), 1.5f);  // reported, not hidden
}

TEST(CameraMatch, LeavesSmallDifferencesAndUnknownCamerasAlone) {
  auto m = plan_camera_match({{"cam0", {1.003f, 1.002f, 0.998f}}, {"cam1", {1, 1, 1}}},
                             {camera("cam0", 6), camera("cam1", 6), camera("cam9", 6)});
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->changes.empty());
  EXPECT_EQ(m->left.count("cam9"), 0u);  // no estimate: not touched, not reported
  auto strict = plan_camera_match({{"cam0", {1.003f, 1.002f, 0.998f}}, {"cam1", {1, 1, 1}}},
                                  {camera("cam0", 6), camera("cam1", 6)}, 0);
  ASSERT_TRUE(strict);
  EXPECT_FALSE(strict->changes.empty());
}

TEST(CameraMatch, RefusesBadInputInOneLine) {
  const std::vector<CameraControls> rig = {camera("cam0")};
  for (const Eigen::Vector3f& e :
       {Eigen::Vector3f(NAN, 1, 1), Eigen::Vector3f(0, 1, 1), Eigen::Vector3f(1, -1, 1)}) {
    auto m = plan_camera_match({{"cam0", e}}, rig);
    ASSERT_FALSE(m);
    EXPECT_NE(m.error().message.find("cam0"), std::string::npos);
    EXPECT_EQ(m.error().message.find('\n'), std::string::npos);
  }
  CameraControls bad = camera("cam0");
  bad.gain_db = ControlValue{0, 24, 0};
  EXPECT_FALSE(plan_camera_match({{"cam0", {1, 1, 1}}}, {bad}));
  bad = camera("cam0");
  bad.ratio_red->max = INFINITY;
  EXPECT_FALSE(plan_camera_match({{"cam0", {1, 1, 1}}}, {bad}));
  EXPECT_FALSE(plan_camera_match({{"cam0", {1, 1, 1}}}, rig, -0.1));
  // A ratio read back as 0 (the channel off) is left alone, reported as left over.
  CameraControls off = camera("cam0");
  off.ratio_red->value = 0;
  auto m = plan_camera_match({{"cam0", {1.2f, 1, 1}}}, {off});
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->changes.empty());
  EXPECT_NEAR(m->left.at("cam0").x(), 1.2f, 1e-5);
  EXPECT_TRUE(plan_camera_match({{"cam0", {1, 1, 1}}}, rig));  // the positive control
}

}  // namespace
}  // namespace studio::preview

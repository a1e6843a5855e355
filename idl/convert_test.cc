#include "wire/convert.h"

#include <gtest/gtest.h>

#include <random>

#include "wire/sample.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

RunMask random_mask(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  Mask m(w, h, 0);
  // A blob plus speckle: realistic runs and edge cases.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m(x, y) = ((x - w / 2) * (x - w / 2) + (y - h / 2) * (y - h / 2) < w * h / 8 || rng() % 50 == 0) ? 255 : 0;
  return RunMask::from_mask(m.view());
}

TEST(Convert, MaskRoundTripsInBothEncodings) {
  const RunMask mask = random_mask(97, 61, 3);
  for (auto enc : {studio_MASK_RUNS, studio_MASK_CODEC}) {
    Owned<studio_AlphaMask> s;
    from_core(mask, enc, *s);
    set(s->camera_id, "cam0");
    EXPECT_EQ(validate(*s), std::nullopt);
    auto back = to_core(*s);
    ASSERT_TRUE(back.has_value()) << back.error().message;
    EXPECT_EQ(*back, mask);
  }
}

TEST(Convert, MaskCodecSizeMismatchIsAnError) {
  Owned<studio_AlphaMask> s;
  from_core(random_mask(40, 30, 1), studio_MASK_CODEC, *s);
  set(s->camera_id, "cam3");
  s->width = 41;
  auto back = to_core(*s);
  ASSERT_FALSE(back.has_value());
  EXPECT_NE(back.error().message.find("cam3"), std::string::npos);
}

TEST(Convert, ProjectorMaskRoundTripsAndValidates) {
  const RunMask m = random_mask(96, 54, 4);
  Owned<studio_ProjectorMask> s;
  set(s->projector_id, "proj0");
  s->step = 2;
  from_core(m, *s);
  EXPECT_FALSE(validate(*s));
  auto back = to_core(*s);
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(*back, m);
  s->step = 0;
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s->step = 2;
  s->height = 53;  // the run table no longer fits the header
  EXPECT_EQ(validate(*s), Reject::bad_size);
  auto bad = to_core(*s);
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("proj0"), std::string::npos);
}

TEST(Convert, CameraRoundTrips) {
  Camera c;
  c.id = "cam1";
  c.width = 704;
  c.height = 576;
  c.intrinsics = {.fx = 700, .fy = 702, .cx = 350.5, .cy = 290.25, .skew = 0};
  c.distortion = Distortion::radial(-0.12, 0.03);
  c.cam_from_world = Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
                            Eigen::Vector3d(0.1, -1.5, 4.0));
  Owned<studio_CameraCalibration> s;
  ASSERT_TRUE(from_core(c, *s).has_value());
  EXPECT_EQ(validate(*s), std::nullopt);
  auto back = to_core(*s);
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->id, "cam1");
  EXPECT_NEAR((back->projection_matrix() - c.projection_matrix()).norm(), 0, 1e-9);
  EXPECT_EQ(back->distortion.rd3, -0.12);

  c.distortion = Distortion::opencv(0.1, 0, 0, 0, 0);
  EXPECT_FALSE(from_core(c, *s).has_value());
  s->R[0] = 2;  // not a rotation
  EXPECT_FALSE(to_core(*s).has_value());
}

}  // namespace
}  // namespace studio::wire

// Camera-topic conversions of the capture node (wire/capture_convert.h): headers and payloads, and
// the explicit camera model conversion of CameraCalibration (OpenCV distortion is fitted to the
// paper's model or refused, never renamed).
#include "wire/capture_convert.h"

#include <gtest/gtest.h>

#include "core/look_at.h"
#include "wire/convert.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

Camera camera(const Distortion& d) {
  Camera c;
  c.id = "cam4";
  c.width = 704;
  c.height = 576;
  c.intrinsics = {.fx = 600, .fy = 600, .cx = 351.5, .cy = 287.5, .skew = 0};
  c.distortion = d;
  c.cam_from_world = look_at({3, 2, 1}, {0, 1, 0});
  return c;
}

TEST(CaptureConvert, CalibrationCarriesThePapersModelWithTheHeader) {
  Owned<studio_CameraCalibration> s;
  auto fit = from_core(camera(Distortion::radial(-0.15, 0.02)), 42, 123456789, true, s);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_FALSE(fit->fitted);
  EXPECT_EQ(validate(*s), std::nullopt);
  EXPECT_STREQ(s->camera_id, "cam4");
  EXPECT_EQ(s->frame, 42u);
  EXPECT_EQ(s->capture_ns, 123456789);
  EXPECT_TRUE(s->tracked);
  EXPECT_EQ(s->rd3, -0.15);
  EXPECT_EQ(s->rd5, 0.02);
}

TEST(CaptureConvert, RadialOnlyOpenCvCalibrationIsConvertedWithZeroResidual) {
  Owned<studio_CameraCalibration> s;
  auto fit = from_core(camera(Distortion::opencv(-0.18, 0.025, 0, 0, 0)), 1, 2, false, s);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_TRUE(fit->fitted);
  EXPECT_LT(fit->max_residual_px, 1e-6);
  EXPECT_NEAR(s->rd3, -0.18, 1e-9);
  EXPECT_NEAR(s->rd5, 0.025, 1e-9);
  auto back = to_core(*s);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->distortion.model, Distortion::Model::radial);
}

TEST(CaptureConvert, TangentialOpenCvCalibrationIsRefused) {
  Owned<studio_CameraCalibration> s;
  auto fit = from_core(camera(Distortion::opencv(-0.18, 0.025, 0.012, 0.01, 0)), 1, 2, false, s);
  ASSERT_FALSE(fit);
  EXPECT_NE(fit.error().message.find("camera cam4"), std::string::npos);
  EXPECT_NE(fit.error().message.find("does not fit the paper's radial model"), std::string::npos)
      << fit.error().message;
}

TEST(CaptureConvert, StateCommandControlAndImage) {
  CameraStateCore st;
  st.camera_id = "cam1";
  st.frame = 9;
  st.features = {{"Gain", 3, 0, 24, true}, {"ExposureTime", 5000, 20, 40000, true}};
  st.fps = 25;
  st.take = "t1";
  st.state = CameraStateCore::Run::kRecording;
  Owned<studio_CameraState> state;
  from_core(st, state);
  EXPECT_EQ(validate(*state), std::nullopt);
  EXPECT_EQ(state->state, studio_CAMERA_RECORDING);
  ASSERT_EQ(view(state->features).size(), 2u);
  EXPECT_STREQ(view(state->features)[1].name, "ExposureTime");

  Owned<studio_CaptureCommand> cmd;
  set(cmd->take, "take7");
  cmd->action = studio_CAPTURE_STOP;
  cmd->at_frame = 77;
  const CaptureCommandCore c = to_core(*cmd);
  EXPECT_EQ(c.take, "take7");
  EXPECT_FALSE(c.start);
  EXPECT_EQ(c.at_frame, 77u);

  Owned<studio_CameraControl> ctl;
  set(ctl->camera_id, "cam2");
  set(ctl->feature, "Gain");
  ctl->value = 6;
  const CameraControlCore k = to_core(*ctl);
  EXPECT_EQ(k.camera_id, "cam2");
  EXPECT_EQ(k.feature, "Gain");
  EXPECT_EQ(k.value, 6);

  Owned<studio_CameraImage> image;
  from_core("cam3", 5, 6, 2, 1, false, {1, 2, 3, 4, 5, 6}, image);
  EXPECT_EQ(validate(*image), std::nullopt);
  EXPECT_EQ(image->format, studio_IMAGE_RGB8);
  Owned<studio_AlphaMask> mask;
  from_core("cam3", 5, 6, encode_mask(RunMask(8, 4)), 8, 4, mask);
  EXPECT_EQ(validate(*mask), std::nullopt);
  auto decoded = to_core(*mask);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(decoded->width(), 8);
}

}  // namespace
}  // namespace studio::wire

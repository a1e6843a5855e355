#include "core/distortion_fit.h"

#include <gtest/gtest.h>

#include <random>

#include "core/look_at.h"

namespace studio {
namespace {

Camera opencv_camera(const std::string& id, Distortion d) {
  Camera c;
  c.id = id;
  c.width = 704;
  c.height = 576;
  c.intrinsics = {.fx = 620, .fy = 615, .cx = 351.5, .cy = 287.5, .skew = 0.2};
  c.distortion = d;
  c.cam_from_world = look_at({3, 1.8, 2}, {0, 1, 0});
  return c;
}

// Pixel distance between the two cameras' images of random world points the input camera sees.
double max_reprojection_px(const Camera& a, const Camera& b) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  double worst = 0;
  int seen = 0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d x(u(rng), 1 + u(rng), u(rng));
    Eigen::Vector2d pa, pb;
    if (!a.project(x, &pa) || !a.in_image(pa) || !b.project(x, &pb)) continue;
    worst = std::max(worst, (pa - pb).norm());
    ++seen;
  }
  EXPECT_GT(seen, 1000);
  return worst;
}

TEST(PaperModel, RadialOnlyOpenCvConvertsExactly) {
  const Camera c = opencv_camera("cam0", Distortion::opencv(-0.21, 0.034, 0, 0, 0));
  auto fit = to_paper_model(c);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_TRUE(fit->fitted);
  EXPECT_EQ(fit->camera.distortion.model, Distortion::Model::radial);
  EXPECT_NEAR(fit->camera.distortion.rd3, -0.21, 1e-9);
  EXPECT_NEAR(fit->camera.distortion.rd5, 0.034, 1e-9);
  EXPECT_LT(fit->max_residual_px, 1e-6);
  EXPECT_LT(fit->rms_residual_px, 1e-6);
  EXPECT_GT(fit->samples, 41 * 41 / 2);
  EXPECT_LT(max_reprojection_px(c, fit->camera), 1e-6);
}

TEST(PaperModel, SmallK3IsFittedWithItsResidualReported) {
  const Camera c = opencv_camera("cam1", Distortion::opencv(-0.2, 0.03, 0, 0, 0.004));
  auto fit = to_paper_model(c);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_GT(fit->max_residual_px, 1e-4);  // k3 is not representable: a real fit, not a rename
  EXPECT_LE(fit->max_residual_px, 0.5);
  EXPECT_LE(fit->rms_residual_px, fit->max_residual_px);
  // The reported residual is what projecting through the fitted camera costs (same direction:
  // ideal -> observed in both models).
  EXPECT_LE(max_reprojection_px(c, fit->camera), fit->max_residual_px * 1.05 + 1e-9);
  // A plain rename (rd3 = k1, rd5 = k2) would be worse than the fit.
  Camera renamed = c;
  renamed.distortion = Distortion::radial(c.distortion.k1, c.distortion.k2);
  EXPECT_GT(max_reprojection_px(c, renamed), fit->max_residual_px);
}

TEST(PaperModel, StronglyTangentialIsRefused) {
  const Camera c = opencv_camera("cam7", Distortion::opencv(-0.2, 0.03, 0.01, -0.008, 0));
  auto fit = to_paper_model(c);
  ASSERT_FALSE(fit);
  const std::string& m = fit.error().message;
  EXPECT_NE(m.find("camera cam7"), std::string::npos) << m;
  EXPECT_NE(m.find("does not fit the paper's radial model"), std::string::npos) << m;
  EXPECT_NE(m.find("exceeds 0.5 px"), std::string::npos) << m;
  // A looser tolerance accepts it, with the residual that the strict one refused.
  auto loose = to_paper_model(c, {.max_residual_px = 50});
  ASSERT_TRUE(loose) << loose.error().message;
  EXPECT_GT(loose->max_residual_px, 0.5);
}

TEST(PaperModel, PaperAndNoDistortionPassUnchanged) {
  for (const Distortion& d : {Distortion::none(), Distortion::radial(-0.1, 0.02)}) {
    const Camera c = opencv_camera("cam2", d);
    auto fit = to_paper_model(c);
    ASSERT_TRUE(fit);
    EXPECT_FALSE(fit->fitted);
    EXPECT_EQ(fit->camera.distortion.model, d.model);
    EXPECT_EQ(fit->camera.distortion.rd3, d.rd3);
    EXPECT_EQ(fit->max_residual_px, 0);
  }
}

TEST(PaperModel, BadOptionsAndSizesAreErrors) {
  const Camera c = opencv_camera("cam3", Distortion::opencv(-0.2, 0.03, 0, 0, 0));
  EXPECT_FALSE(to_paper_model(c, {.max_residual_px = 0}));
  EXPECT_FALSE(to_paper_model(c, {.grid = 2}));
  Camera sizeless = c;
  sizeless.width = 0;
  auto fit = to_paper_model(sizeless);
  ASSERT_FALSE(fit);
  EXPECT_NE(fit.error().message.find("image size"), std::string::npos);
}

}  // namespace
}  // namespace studio

#include "core/camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>

#include "core/look_at.h"

namespace studio {
namespace {

// A camera looking at the studio origin from `centre`, y up in the world appearing as -v.
Camera camera_looking_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double f,
                         int w, int h) {
  Camera c;
  c.id = "cam";
  c.width = w;
  c.height = h;
  c.intrinsics.fx = f;
  c.intrinsics.fy = f * 1.02;
  c.intrinsics.cx = w / 2.0 + 3.25;
  c.intrinsics.cy = h / 2.0 - 4.5;
  c.intrinsics.skew = 0.75;
  c.cam_from_world = look_at(centre, target);
  return c;
}

std::vector<Camera> test_cameras() {
  std::vector<Camera> cams;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 20; ++i) {
    const double angle = i * 0.7;
    const Eigen::Vector3d centre(4 * std::cos(angle), 1.5 + u(rng), 4 * std::sin(angle));
    Camera c = camera_looking_at(centre, Eigen::Vector3d(u(rng) * 0.3, 1, u(rng) * 0.3), 700 + 100 * u(rng),
                       704, 576);
    c.intrinsics.skew = (i % 3 == 0) ? 0.0 : 2 * u(rng);
    cams.push_back(c);
  }
  return cams;
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

TEST(Distortion, IdentityModels) {
  EXPECT_TRUE(Distortion::none().is_identity());
  EXPECT_TRUE(Distortion::radial(0, 0).is_identity());
  EXPECT_FALSE(Distortion::radial(0.1, 0).is_identity());
  EXPECT_FALSE(Distortion::opencv(0, 0, 0.001, 0, 0).is_identity());
  const Eigen::Vector2d p(0.3, -0.2);
  EXPECT_EQ(distort(Distortion::none(), p), p);
}

TEST(Distortion, RadialIsThePapersPolynomialOnTheRadius) {
  const Distortion d = Distortion::radial(-0.21, 0.05);
  const Eigen::Vector2d ideal(0.3, -0.4);  // r' = 0.5
  const Eigen::Vector2d observed = distort(d, ideal);
  const double r_prime = 0.5;
  const double r = r_prime - 0.21 * std::pow(r_prime, 3) + 0.05 * std::pow(r_prime, 5);
  EXPECT_NEAR(observed.norm(), r, 1e-15);
  EXPECT_NEAR(observed.normalized().dot(ideal.normalized()), 1.0, 1e-15);
}

// distort then undistort over every pixel of a 704x576 image (sampled every 4 px), measured in
// pixels of a 700 px focal length. Strong distortion: 25% barrel at the corners.
void check_undistort_over_image(const Distortion& d, const char* label) {
  const double f = 700, cx = 352, cy = 288;
  double worst_px = 0;
  for (int v = 0; v < 576; v += 4) {
    for (int u = 0; u < 704; u += 4) {
      const Eigen::Vector2d observed((u - cx) / f, (v - cy) / f);
      const Eigen::Vector2d ideal = undistort(d, observed);
      const Eigen::Vector2d back = distort(d, ideal);
      worst_px = std::max(worst_px, (back - observed).norm() * f);
      // and the other way: ideal grid → observed → ideal
      const Eigen::Vector2d again = undistort(d, distort(d, observed));
      worst_px = std::max(worst_px, (again - observed).norm() * f);
    }
  }
  std::printf("[ measured ] %s: max distort/undistort round trip %.3g px\n", label, worst_px);
  EXPECT_LT(worst_px, 1e-6) << label;
}

TEST(Distortion, UndistortInvertsDistortOverTheWholeImage) {
  check_undistort_over_image(Distortion::radial(-0.08, 0.01), "radial typical");
  check_undistort_over_image(Distortion::radial(-0.35, 0.12), "radial strong");
  check_undistort_over_image(Distortion::radial(0.25, 0.05), "radial pincushion");
  check_undistort_over_image(Distortion::opencv(-0.12, 0.05, 0.0008, -0.0005, -0.01),
                             "opencv typical");
  check_undistort_over_image(Distortion::opencv(-0.38, 0.16, 0.003, -0.002, -0.03),
                             "opencv strong");
}

TEST(Distortion, OpenCvModelMatchesProjectPoints) {
  const Camera base = test_cameras()[3];
  const Distortion d = Distortion::opencv(-0.28, 0.09, 0.0012, -0.0007, -0.015);
  Camera cam = base;
  cam.distortion = d;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<cv::Point3d> object;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d x(u(rng), 1 + u(rng), u(rng));
    points.push_back(x);
    object.emplace_back(x.x(), x.y(), x.z());
  }
  const Eigen::Matrix3d R = cam.cam_from_world.R();
  cv::Mat Rm(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F), K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      Rm.at<double>(r, c) = R(r, c);
      K.at<double>(r, c) = cam.intrinsics.K()(r, c);
    }
    tvec.at<double>(r) = cam.cam_from_world.translation(r);
  }
  cv::Rodrigues(Rm, rvec);
  const cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, rvec, tvec, K, dist, image);
  double worst = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d p;
    ASSERT_TRUE(cam.project(points[i], &p));
    worst = std::max(worst, (p - Eigen::Vector2d(image[i].x, image[i].y)).norm());
  }
  std::printf("[ measured ] max |project - cv::projectPoints| = %.3g px\n", worst);
  EXPECT_LT(worst, 1e-8);  // Rodrigues round trip limits the agreement, not the model
}

TEST(Intrinsics, KRoundTripAndNormalisation) {
  Intrinsics k{812.5, 790.25, 351.5, 287.75, 1.5};
  const Intrinsics back = Intrinsics::from_K(3.5 * k.K());
  EXPECT_NEAR(back.fx, k.fx, 1e-12);
  EXPECT_NEAR(back.fy, k.fy, 1e-12);
  EXPECT_NEAR(back.cx, k.cx, 1e-12);
  EXPECT_NEAR(back.cy, k.cy, 1e-12);
  EXPECT_NEAR(back.skew, k.skew, 1e-12);
}

TEST(Camera, CentreAxisProjectUnproject) {
  const Distortion d = Distortion::radial(-0.2, 0.04);
  double worst_point = 0, worst_ray = 0;
  for (Camera cam : test_cameras()) {
    cam.distortion = d;
    const Eigen::Vector3d C = cam.centre_in_world();
    EXPECT_LT((cam.cam_from_world * C).norm(), 1e-12);
    EXPECT_NEAR((cam.cam_from_world.R() * cam.axis_in_world() - Eigen::Vector3d::UnitZ()).norm(), 0,
                1e-12);
    for (int v = 0; v < cam.height; v += 48) {
      for (int u = 0; u < cam.width; u += 64) {
        const Eigen::Vector2d pixel(u, v);
        const Eigen::Vector3d X = cam.unproject(pixel, 3.7);
        EXPECT_NEAR((cam.cam_from_world * X).z(), 3.7, 1e-12);
        Eigen::Vector2d back;
        ASSERT_TRUE(cam.project(X, &back));
        worst_point = std::max(worst_point, (back - pixel).norm());
        const Eigen::Vector3d ray = cam.pixel_ray_in_world(pixel);
        EXPECT_NEAR(ray.norm(), 1, 1e-12);
        worst_ray = std::max(worst_ray, ((X - C).normalized() - ray).norm());
      }
    }
    Eigen::Vector2d untouched(-1, -1);
    EXPECT_FALSE(cam.project(C - cam.axis_in_world(), &untouched));
    EXPECT_FALSE(cam.project(C - 1e-6 * cam.axis_in_world(), &untouched));
    EXPECT_EQ(untouched, Eigen::Vector2d(-1, -1));
  }
  std::printf("[ measured ] project(unproject(px)) max error %.3g px, ray error %.3g\n",
              worst_point, worst_ray);
  EXPECT_LT(worst_point, 1e-9);
  EXPECT_LT(worst_ray, 1e-12);
}

TEST(Camera, ProjectionMatrixAgreesWithProjectWithoutDistortion) {
  for (const Camera& cam : test_cameras()) {
    const Eigen::Matrix<double, 3, 4> P = cam.projection_matrix();
    const Eigen::Vector3d X(0.2, 1.3, -0.4);
    Eigen::Vector2d p;
    ASSERT_TRUE(cam.project(X, &p));
    const Eigen::Vector3d h = P * X.homogeneous();
    EXPECT_LT((h.hnormalized() - p).norm(), 1e-9);
  }
}

TEST(Cahv, RoundTripIsExactIncludingSkew) {
  double worst_k = 0, worst_R = 0, worst_t = 0, worst_px = 0;
  for (const Camera& cam : test_cameras()) {
    const Cahv cahv = to_cahv(cam);
    EXPECT_NEAR(cahv.A.norm(), 1, 1e-14);
    // The CAHV equations project as the camera does.
    const Eigen::Vector3d X(0.3, 0.9, 0.1);
    Eigen::Vector2d p;
    ASSERT_TRUE(cam.project(X, &p));
    const Eigen::Vector3d d = X - cahv.C;
    worst_px = std::max(worst_px,
                        (Eigen::Vector2d(d.dot(cahv.H), d.dot(cahv.V)) / d.dot(cahv.A) - p).norm());
    Expected<Camera> back = camera_from_cahv(cahv, cam.width, cam.height);
    ASSERT_TRUE(back) << back.error().message;
    worst_k = std::max(worst_k, max_abs(back->intrinsics.K() - cam.intrinsics.K()));
    worst_R = std::max(worst_R, max_abs(back->cam_from_world.R() - cam.cam_from_world.R()));
    worst_t = std::max(worst_t,
                       max_abs(back->cam_from_world.translation - cam.cam_from_world.translation));
    EXPECT_EQ(back->width, cam.width);
    // A non-unit A describes the same camera.
    Cahv scaled = cahv;
    scaled.A *= 2.5;
    scaled.H *= 2.5;
    scaled.V *= 2.5;
    Expected<Camera> back2 = camera_from_cahv(scaled, cam.width, cam.height);
    ASSERT_TRUE(back2);
    EXPECT_LT(max_abs(back2->projection_matrix() - cam.projection_matrix()), 1e-9);
  }
  std::printf(
      "[ measured ] K/Rt -> CAHV -> K/Rt max error: K %.3g, R %.3g, t %.3g; CAHV "
      "projection %.3g px\n",
      worst_k, worst_R, worst_t, worst_px);
  EXPECT_LT(worst_k, 1e-9);
  EXPECT_LT(worst_R, 1e-9);
  EXPECT_LT(worst_t, 1e-9);
  EXPECT_LT(worst_px, 1e-9);
}

TEST(Cahv, RejectsDegenerateAndLeftHanded) {
  Cahv c;
  c.A = Eigen::Vector3d::Zero();
  EXPECT_FALSE(camera_from_cahv(c, 10, 10));
  c = Cahv{};
  c.V = c.A * 3;
  EXPECT_FALSE(camera_from_cahv(c, 10, 10));
  c = Cahv{};
  c.H = -c.H;
  Expected<Camera> left = camera_from_cahv(c, 10, 10);
  ASSERT_FALSE(left);
  EXPECT_NE(left.error().message.find("left-handed"), std::string::npos);
  c = Cahv{};
  c.C.x() = std::nan("");
  EXPECT_FALSE(camera_from_cahv(c, 10, 10));
  EXPECT_FALSE(camera_from_cahv(Cahv{}, -1, 10));
}

TEST(ProjectionMatrix, DecompositionRecoversCameraForAnyScaleAndSign) {
  double worst_P = 0, worst_k = 0, worst_R = 0;
  for (const Camera& cam : test_cameras()) {
    const Eigen::Matrix<double, 3, 4> P = cam.projection_matrix();
    for (double scale : {1.0, -1.0, 1e-4, -37.5, 2e5}) {
      Expected<Camera> back = camera_from_projection_matrix(scale * P, cam.width, cam.height);
      ASSERT_TRUE(back) << back.error().message;
      EXPECT_NEAR(back->cam_from_world.R().determinant(), 1, 1e-12);
      EXPECT_GT(back->intrinsics.fx, 0);
      EXPECT_GT(back->intrinsics.fy, 0);
      const Eigen::Matrix<double, 3, 4> P2 = back->projection_matrix();
      // K(2,2) = 1 on both sides, so P2 must equal P exactly (no residual scale).
      worst_P = std::max(worst_P, max_abs(P2 - P) / max_abs(P));
      worst_k = std::max(worst_k, max_abs(back->intrinsics.K() - cam.intrinsics.K()));
      worst_R = std::max(worst_R, max_abs(back->cam_from_world.R() - cam.cam_from_world.R()));
    }
  }
  std::printf("[ measured ] P -> camera -> P max relative error %.3g; K %.3g; R %.3g\n", worst_P,
              worst_k, worst_R);
  EXPECT_LT(worst_P, 1e-9);
  EXPECT_LT(worst_k, 1e-9);
  EXPECT_LT(worst_R, 1e-9);
}

TEST(ProjectionMatrix, RejectsRankDeficientAndNonFinite) {
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  EXPECT_FALSE(camera_from_projection_matrix(P, 10, 10));
  P << 1, 2, 3, 4, 2, 4, 6, 8, 0, 0, 1, 1;  // rows 0 and 1 parallel
  Expected<Camera> bad = camera_from_projection_matrix(P, 10, 10);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("rank"), std::string::npos);
  P = test_cameras()[0].projection_matrix();
  P(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(camera_from_projection_matrix(P, 10, 10));
}

}  // namespace
}  // namespace studio

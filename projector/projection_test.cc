// Projection geometry (projector/projector_view.h): for random eyes and scene points, the projector
// pixel given by each form must equal the pixel of the point where the ray from the eye through the
// scene point meets the screen, projected by the projector's own camera model (core Camera), which
// this test computes independently (ray-plane intersection from the raw corners).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <random>

#include "core/rig.h"
#include "projector/off_axis.h"
#include "projector/projector_view.h"
#include "projector/screen.h"
#include "testing/projectors.h"

namespace studio::projector {
namespace {

using testing::look_at;
using testing::make_projector;
using testing::studio_projectors;

struct Truth {
  bool ok = false;
  Eigen::Vector3d on_screen;
  Eigen::Vector2d pixel;  // observed projector pixel (core Camera::project)
};

// Independent reference: the plane from the raw corners, the ray from the eye through x.
Truth truth(const Projector& p, const Eigen::Vector3d& eye, const Eigen::Vector3d& x) {
  Truth t;
  const Eigen::Vector3d n =
      (p.screen[2] - p.screen[0]).cross(p.screen[3] - p.screen[1]).normalized();
  const double denom = n.dot(x - eye);
  if (std::abs(denom) < 1e-9) return t;
  const double lambda = n.dot(p.screen[0] - eye) / denom;
  if (!(lambda > 0)) return t;
  t.on_screen = eye + lambda * (x - eye);
  // Compared where the projector has pixels (the homography holds on the whole plane, but far
  // outside the image its pixels grow without bound and so does their rounding).
  t.ok = p.camera.project(t.on_screen, &t.pixel) && p.camera.in_image(t.pixel);
  return t;
}

Eigen::Vector3d random_eye(std::mt19937& rng) {
  std::uniform_real_distribution<double> ux(-1.0, 1.0), uy(1.2, 2.0), uz(-0.6, 1.2);
  return {ux(rng), uy(rng), uz(rng)};
}

Eigen::Vector3d random_point(std::mt19937& rng) {
  std::uniform_real_distribution<double> ux(-6, 6), uy(-1, 5), uz(-8, 4);
  return {ux(rng), uy(rng), uz(rng)};
}

TEST(ProjectionTest, SinglePassLandsWhereTheEyeRayMeetsTheScreen) {
  std::mt19937 rng(7);
  for (const Projector& p : studio_projectors()) {
    auto view = ProjectorView::create(p);
    ASSERT_TRUE(view) << view.error().message;
    int compared = 0;
    double worst = 0;
    for (int e = 0; e < 60; ++e) {
      const Eigen::Vector3d eye = random_eye(rng);
      auto single = view->single_pass(eye);
      ASSERT_TRUE(single) << single.error().message;
      for (int i = 0; i < 400; ++i) {
        const Eigen::Vector3d x = random_point(rng);
        const Truth t = truth(p, eye, x);
        const double depth = -(single->eye.view_from_world * x.homogeneous()).z();
        if (!t.ok || depth < 0.05 || depth > 100) continue;
        const Eigen::Vector4d clip = single->clip_from_world * x.homogeneous();
        ASSERT_GT(clip.w(), 0);
        const Eigen::Vector2d pixel =
            (pixel_from_ndc(1920, 1080) * (clip.head<2>() / clip.w()).homogeneous()).head<2>();
        worst = std::max(worst, (pixel - t.pixel).norm());
        // Inside the eye's depth range and on the screen: inside the projector's depth range.
        const Eigen::Vector2d st = view->screen().coordinates(t.on_screen);
        if (st.x() >= 0 && st.y() >= 0 && st.x() <= view->screen().width &&
            st.y() <= view->screen().height) {
          EXPECT_LE(std::abs(clip.z() / clip.w()), 1.0 + 1e-9);
        }
        EXPECT_GE(single->eye_clip_plane.dot(x.homogeneous()), 0);
        ++compared;
      }
    }
    EXPECT_GT(compared, 2000) << p.camera.id;
    EXPECT_LE(worst, 0.01) << p.camera.id;
    std::printf("single pass, %s: worst %.2e px over %d points\n", p.camera.id.c_str(), worst,
                compared);
  }
}

TEST(ProjectionTest, SinglePassKeepsTheDepthOrderAlongEveryEyeRay) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> frac(0.05, 0.95);
  for (const Projector& p : studio_projectors()) {
    auto view = ProjectorView::create(p);
    ASSERT_TRUE(view) << view.error().message;
    for (int e = 0; e < 20; ++e) {
      const Eigen::Vector3d eye = random_eye(rng);
      auto single = view->single_pass(eye);
      ASSERT_TRUE(single);
      for (int i = 0; i < 100; ++i) {
        // Two points on one eye ray through a random screen point, one in front of the other.
        const Eigen::Vector3d s = view->screen().point(
            {frac(rng) * view->screen().width, frac(rng) * view->screen().height});
        const Eigen::Vector3d dir = (s - eye).normalized();
        const double a = 0.2 + 5 * frac(rng), b = a + 0.01 + 5 * frac(rng);
        const Eigen::Vector4d ca = single->clip_from_world * (eye + a * dir).homogeneous();
        const Eigen::Vector4d cb = single->clip_from_world * (eye + b * dir).homogeneous();
        EXPECT_NEAR((ca.head<2>() / ca.w() - cb.head<2>() / cb.w()).norm(), 0, 1e-9);
        EXPECT_LT(ca.z() / ca.w(), cb.z() / cb.w());
      }
      // A point behind the eye is removed by the eye clip plane.
      const Eigen::Vector3d behind = eye + 0.5 * view->screen().normal;
      EXPECT_LT(single->eye_clip_plane.dot(behind.homogeneous()), 0);
    }
  }
}

TEST(ProjectionTest, TwoPassWarpLandsWhereTheEyeRayMeetsTheScreen) {
  std::mt19937 rng(13);
  for (const Projector& p : studio_projectors()) {
    auto view = ProjectorView::create(p);
    ASSERT_TRUE(view) << view.error().message;
    double worst = 0, worst_tex = 0;
    int compared = 0;
    for (int e = 0; e < 60; ++e) {
      const Eigen::Vector3d eye = random_eye(rng);
      auto two = view->two_pass(eye);
      ASSERT_TRUE(two) << two.error().message;
      EXPECT_TRUE(two->exact);
      for (int i = 0; i < 400; ++i) {
        const Eigen::Vector3d x = random_point(rng);
        const Truth t = truth(p, eye, x);
        const double depth = -(two->eye.view_from_world * x.homogeneous()).z();
        if (!t.ok || depth < 0.05 || depth > 100) continue;
        // Pass 1: the eye's NDC -> texture of the screen; pass 2: texture -> projector pixel.
        const Eigen::Vector4d clip = two->eye.clip_from_world * x.homogeneous();
        const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
        const Eigen::Vector2d tex = 0.5 * (ndc + Eigen::Vector2d::Ones());
        const Eigen::Vector2d pixel = (two->pixel_from_texture * tex.homogeneous()).hnormalized();
        worst = std::max(worst, (pixel - t.pixel).norm());
        // The second pass's own lookups, from the projector pixel back to the texture.
        const Eigen::Vector2d frag(t.pixel.x() + 0.5, 1080 - t.pixel.y() - 0.5);
        const Eigen::Vector2d ndc_p =
            (ndc_from_pixel(1920, 1080) * t.pixel.homogeneous()).head<2>();
        worst_tex = std::max(
            {worst_tex,
             ((two->texture_from_pixel * t.pixel.homogeneous()).hnormalized() - tex).norm(),
             ((two->texture_from_fragcoord * frag.homogeneous()).hnormalized() - tex).norm(),
             ((two->texture_from_ndc * ndc_p.homogeneous()).hnormalized() - tex).norm()});
        ++compared;
      }
    }
    EXPECT_GT(compared, 2000) << p.camera.id;
    EXPECT_LE(worst, 0.01) << p.camera.id;
    // 1e-6 of the texture is ~2-4 micrometres on these screens, far below 0.01 px.
    EXPECT_LE(worst_tex, 1e-6) << p.camera.id;
    std::printf("two pass, %s: worst %.2e px over %d points\n", p.camera.id.c_str(), worst,
                compared);
  }
}

TEST(ProjectionTest, PixelNdcConventionsRoundTrip) {
  const Eigen::Matrix3d m = pixel_from_ndc(1920, 1080) * ndc_from_pixel(1920, 1080);
  EXPECT_LE((m - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  // Pixel centres: the top-left pixel centre is NDC (-1 + 1/W, 1 - 1/H).
  const Eigen::Vector3d top_left = ndc_from_pixel(1920, 1080) * Eigen::Vector3d(0, 0, 1);
  EXPECT_NEAR(top_left.x(), -1 + 1.0 / 1920, 1e-15);
  EXPECT_NEAR(top_left.y(), 1 - 1.0 / 1080, 1e-15);
}

TEST(ProjectionTest, TwoPassWithLensDistortionIsExactThroughTheWarpMap) {
  Projector p = studio_projectors()[0];
  p.camera.distortion = Distortion::radial(-0.04, 0.01);
  auto view = ProjectorView::create(p);
  ASSERT_TRUE(view) << view.error().message;
  auto single = view->single_pass(Eigen::Vector3d(0, 1.6, 0.5));
  ASSERT_FALSE(single);
  EXPECT_NE(single.error().message.find("two-pass"), std::string::npos) << single.error().message;
  auto two = view->two_pass(Eigen::Vector3d(0, 1.6, 0.5));
  ASSERT_TRUE(two);
  EXPECT_FALSE(two->exact);
  const std::vector<float> map = view->warp_map();
  ASSERT_EQ(map.size(), 2u * 1920 * 1080);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> us(0.02, 0.98);
  double worst_m = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector2d st(us(rng) * view->screen().width, us(rng) * view->screen().height);
    const Eigen::Vector3d x = p.screen[0] + st.x() * (p.screen[1] - p.screen[0]).normalized() +
                              st.y() * (p.screen[3] - p.screen[0]).normalized();
    Eigen::Vector2d pixel;
    ASSERT_TRUE(p.camera.project(x, &pixel));
    worst_m = std::max(worst_m, (view->screen_from_observed_pixel(pixel) - st).norm());
  }
  // A projector pixel is ~2 mm on this 4 m screen: 1e-6 m is ~5e-4 px.
  EXPECT_LE(worst_m, 1e-6);
  // The map holds the same lookups at integer pixels.
  for (const Eigen::Vector2i& px :
       {Eigen::Vector2i(0, 0), Eigen::Vector2i(1919, 1079), Eigen::Vector2i(700, 300)}) {
    const Eigen::Vector2d st = view->screen_from_observed_pixel(px.cast<double>());
    const size_t i = 2 * (static_cast<size_t>(px.y()) * 1920 + px.x());
    EXPECT_NEAR(map[i], st.x() / view->screen().width, 1e-6);
    EXPECT_NEAR(map[i + 1], st.y() / view->screen().height, 1e-6);
  }
}

TEST(ProjectionTest, OffAxisMapsTheScreenCornersToTheNdcCorners) {
  const Projector p = studio_projectors()[1];
  auto screen = Screen::from_corners(p.screen);
  ASSERT_TRUE(screen);
  auto view = off_axis_view(*screen, Eigen::Vector3d(0.3, 1.7, 0.2));
  ASSERT_TRUE(view) << view.error().message;
  const Eigen::Vector2d expected[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector4d c = view->clip_from_world * p.screen[i].homogeneous();
    EXPECT_LE((c.head<2>() / c.w() - expected[i]).norm(), 1e-12) << i;
  }
  // The near and far planes: NDC z -1 and +1 at distances near and far along -normal.
  const Eigen::Vector3d eye(0.3, 1.7, 0.2);
  for (auto [d, z] : {std::pair{0.05, -1.0}, std::pair{100.0, 1.0}}) {
    const Eigen::Vector4d c = view->clip_from_world * (eye - d * screen->normal).homogeneous();
    EXPECT_NEAR(c.z() / c.w(), z, 1e-9);
  }
  EXPECT_EQ(view->distance, (eye - p.screen[0]).dot(screen->normal));
  EXPECT_NEAR(view->distance, 2.8, 1e-12);
}

TEST(ProjectionTest, SuggestedTextureCoversEveryProjectorPixel) {
  for (const Projector& p : studio_projectors()) {
    auto view = ProjectorView::create(p);
    ASSERT_TRUE(view);
    const Eigen::Vector2i size = view->suggested_texture_size();
    EXPECT_GT(size.x(), 500) << p.camera.id;
    EXPECT_LE(size.x(), 1920 * 1.2) << p.camera.id;
    EXPECT_GT(size.y(), 300) << p.camera.id;
    EXPECT_LE(size.y(), 1080 * 1.5) << p.camera.id;
  }
}

// ---- bad input: each refusal beside a positive control ------------------------------------

TEST(ProjectionTest, RefusesDegenerateScreens) {
  const Projector good = studio_projectors()[0];
  ASSERT_TRUE(ProjectorView::create(good));
  auto expect_refused = [&](std::array<Eigen::Vector3d, 4> corners, const std::string& word) {
    Projector p = good;
    p.screen = corners;
    auto v = ProjectorView::create(p);
    ASSERT_FALSE(v) << word;
    EXPECT_NE(v.error().message.find(word), std::string::npos) << v.error().message;
    EXPECT_EQ(v.error().message.find('\n'), std::string::npos);
  };
  const auto& c = good.screen;
  // Collinear corners.
  expect_refused({Eigen::Vector3d(-2, 0, -2), Eigen::Vector3d(0, 0, -2), Eigen::Vector3d(2, 0, -2),
                  Eigen::Vector3d(1, 0, -2)},
                 "degenerate");
  // All four at one point.
  expect_refused({c[0], c[0], c[0], c[0]}, "degenerate");
  // Non-planar: one corner 5 cm out of the plane.
  expect_refused({c[0], c[1], c[2] + Eigen::Vector3d(0, 0, 0.05), c[3]}, "not a planar rectangle");
  // Trapezoid: the top edge 20 cm shorter.
  expect_refused({c[0], c[1], c[2] - Eigen::Vector3d(0.1, 0, 0), c[3] + Eigen::Vector3d(0.1, 0, 0)},
                 "not a planar rectangle");
  // Wrong order (a bow tie, a crossed quadrilateral).
  expect_refused({c[0], c[2], c[1], c[3]}, "degenerate");
  expect_refused({c[0], c[1], c[3], c[2]}, "degenerate");
  // Mirrored order: a rectangle whose front faces away from the projector.
  expect_refused({c[1], c[0], c[3], c[2]}, "behind the screen plane");

  // Non-finite.
  expect_refused({c[0], c[1], Eigen::Vector3d(NAN, 0, 0), c[3]}, "non-finite");
  // Positive control: a measured screen off by 3 mm at one corner is accepted.
  Projector measured = good;
  measured.screen[2] += Eigen::Vector3d(0.002, -0.001, 0.002);
  EXPECT_TRUE(ProjectorView::create(measured));
}

TEST(ProjectionTest, RefusesAnEyeBehindOrOnTheScreen) {
  auto view = ProjectorView::create(studio_projectors()[0]);  // back wall at z = -2, facing +z
  ASSERT_TRUE(view);
  EXPECT_TRUE(view->single_pass({0, 1.6, -1.9}));  // positive control: 10 cm in front
  EXPECT_TRUE(view->two_pass({0, 1.6, -1.9}));
  for (const Eigen::Vector3d& eye : {Eigen::Vector3d(0, 1.6, -2), Eigen::Vector3d(0, 1.6, -2.5),
                                     Eigen::Vector3d(0, 1.6, -1.99)}) {
    auto single = view->single_pass(eye);
    ASSERT_FALSE(single);
    EXPECT_TRUE(single.error().message.find("behind") != std::string::npos ||
                single.error().message.find("at least") != std::string::npos)
        << single.error().message;
    EXPECT_FALSE(view->two_pass(eye));
  }
  EXPECT_FALSE(view->single_pass({NAN, 1.6, 0}));
  OffAxisOptions bad;
  bad.far_m = 0.01;
  EXPECT_FALSE(view->single_pass({0, 1.6, 0}, bad));
}

TEST(ProjectionTest, RefusesAProjectorThatDoesNotSeeItsScreen) {
  const Projector good = studio_projectors()[0];
  ASSERT_TRUE(ProjectorView::create(good));
  auto message = [](const Projector& p) {
    auto v = ProjectorView::create(p);
    return v ? std::string() : v.error().message;
  };
  // Behind the screen plane, looking at the back of the cloth.
  Projector behind = good;
  behind.camera.cam_from_world = look_at({0, 1.5, -6}, {0, 1.25, -2}, 0);
  EXPECT_NE(message(behind).find("behind the screen plane"), std::string::npos) << message(behind);
  // Turned around: the screen is behind the projector.
  Projector away = good;
  away.camera.cam_from_world = look_at({0, 2, 2}, {0, 2, 6}, 0);
  EXPECT_NE(message(away).find("behind the projector"), std::string::npos) << message(away);
  // Aimed to the side: the screen is in front but outside the image.
  Projector aside = good;
  aside.camera.cam_from_world = look_at({0, 2, 8}, {-12, 2, -2}, 0);
  EXPECT_NE(message(aside).find("outside the projector image"), std::string::npos)
      << message(aside);
  // An invalid camera.
  Projector zero = good;
  zero.camera.intrinsics.fx = 0;
  EXPECT_FALSE(ProjectorView::create(zero));
}

}  // namespace
}  // namespace studio::projector

// The static-scene displacement bound of the projector's scene cache (projector/static_shift.h):
// for random eye moves and random scene points seen through the screen from both eyes, the true
// displacement of the point's projector pixel (ray from the eye through the point meets the plane
// of the raw corners, projected by the projector's camera model: computed here, independently of
// the library) never exceeds the bound, and the bound is not loose (its worst ratio is reached
// within a factor of 3). The isotropic allowed move keeps every point within the set pixels.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "projector/projector_view.h"
#include "projector/static_shift.h"
#include "testing/projectors.h"

namespace studio::projector {
namespace {

std::optional<Eigen::Vector2d> pixel_of(const Projector& p, const Eigen::Vector3d& eye,
                                        const Eigen::Vector3d& x) {
  const Eigen::Vector3d n =
      (p.screen[1] - p.screen[0]).cross(p.screen[3] - p.screen[0]).normalized();
  const double denom = n.dot(x - eye);
  if (std::abs(denom) < 1e-12) return std::nullopt;
  const double lambda = n.dot(p.screen[0] - eye) / denom;
  if (!(lambda > 0)) return std::nullopt;
  // Inside the rectangle only (what the frame shows).
  const Eigen::Vector3d on = eye + lambda * (x - eye);
  const Eigen::Vector3d e0 = p.screen[1] - p.screen[0], e1 = p.screen[3] - p.screen[0];
  const double s = (on - p.screen[0]).dot(e0) / e0.squaredNorm(),
               t = (on - p.screen[0]).dot(e1) / e1.squaredNorm();
  if (s < 0 || s > 1 || t < 0 || t > 1) return std::nullopt;
  Eigen::Vector2d px;
  if (!p.camera.project(on, &px)) return std::nullopt;
  return px;
}

TEST(StaticShiftBound, TrueDisplacementStaysUnderTheBoundAndTheBoundIsTight) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  for (const Projector& p : testing::studio_projectors()) {
    auto view = ProjectorView::create(p).value();
    auto bound = StaticShiftBound::create(view);
    ASSERT_TRUE(bound) << bound.error().message;
    const Screen& sc = view.screen();
    double worst_ratio = 0;
    int measured = 0;
    for (int trial = 0; trial < 400; ++trial) {
      // An eye 0.4..2.5 m in front of the screen, over its middle; heights in a random range.
      const Eigen::Vector3d eye = sc.point({sc.width * (0.2 + 0.6 * u(rng)),
                                            sc.height * (0.3 + 0.5 * u(rng))}) +
                                  (0.4 + 2.1 * u(rng)) * sc.normal;
      const double h_e = sc.signed_distance(eye);
      HeightRange r{-12.0 * u(rng), (h_e - 0.1) * u(rng)};
      Eigen::Vector3d d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      d *= (trial % 2 ? 0.002 : 0.05) / d.norm();
      const Eigen::Vector3d eye1 = eye + d;
      const double b = bound->shift_px(r, eye, eye1);
      ASSERT_TRUE(std::isfinite(b));
      // Points at both ends of the height range and between, seen through the screen.
      for (int k = 0; k < 40; ++k) {
        const double h = k < 10 ? r.lo : k < 20 ? r.hi : r.lo + (r.hi - r.lo) * u(rng);
        const Eigen::Vector3d on = sc.point({sc.width * u(rng), sc.height * u(rng)});
        // On the ray eye -> on, at height h: eye + a (on - eye) with h_e + a (0 - h_e) = h.
        const Eigen::Vector3d x = eye + (h_e - h) / h_e * (on - eye);
        auto p0 = pixel_of(p, eye, x), p1 = pixel_of(p, eye1, x);
        if (!p0 || !p1) continue;
        const double moved = (*p1 - *p0).norm();
        ASSERT_LE(moved, b * (1 + 1e-9) + 1e-9)
            << p.camera.id << " trial " << trial << " h " << h << " range " << r.lo << " "
            << r.hi;
        if (b > 1e-6) worst_ratio = std::max(worst_ratio, moved / b);
        ++measured;
      }
      // The isotropic allowed move: any direction at that length stays within the set pixels
// (to first order in the move).
      const double m = bound->allowed_move_m(r, eye, 0.5);
      ASSERT_GT(m, 0);
      // (first order: f and the slope at the far end of the move differ by O(|d|))
      if (std::isfinite(m)) {
        EXPECT_LE(bound->shift_px(r, eye, eye + m * d.normalized()), 0.5 * 1.01);
      }
    }
    std::printf("%s: %d points, %.0f px/m, worst true/bound %.2f\n", p.camera.id.c_str(),
                measured, bound->pixels_per_metre(), worst_ratio);
    EXPECT_GT(measured, 4000);
    EXPECT_GT(worst_ratio, 0.33) << "the bound is loose";
  }
}

TEST(StaticShiftBound, PointsOnTheScreenDoNotMoveAndAnEyeBehindItHasNoBound) {
  const Projector p = testing::studio_projectors()[0];
  auto view = ProjectorView::create(p).value();
  auto bound = StaticShiftBound::create(view).value();
  const Eigen::Vector3d eye = view.screen().point({2, 1.5}) + 2.0 * view.screen().normal;
  EXPECT_EQ(bound.shift_px({0, 0}, eye, eye + Eigen::Vector3d(0.3, 0.1, 0.2)), 0);
  EXPECT_GT(bound.shift_px({-5, 0}, eye, eye + Eigen::Vector3d(0.01, 0, 0)), 1);
  EXPECT_TRUE(std::isinf(bound.shift_px({-5, 0}, eye, eye - 3.0 * view.screen().normal)));
  SceneCacheOptions o;
  EXPECT_TRUE(o.validate());
  o.max_error_px = 0;
  EXPECT_FALSE(o.validate());
}

}  // namespace
}  // namespace studio::projector

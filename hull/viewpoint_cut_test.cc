#include "hull/viewpoint_cut.h"

#include <gtest/gtest.h>

#include "support/cameras.h"
#include "support/masks.h"
#include "testing/synthetic.h"

namespace studio::hull {
namespace {

TEST(ViewpointCut, ProjectorMaskCoversTheActorWithConservativeDepth) {
  const testing::Scene scene = testing::actor();
  auto cams = support::camera_ring(8, 704, 576, 4.0, 1.6, {0, 1, 0}, 600);
  std::vector<RunMask> masks;
  std::vector<View> views;
  for (const Camera& c : cams) masks.push_back(testing::render_mask(c, scene));
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  // A projector-like viewpoint between two cameras, higher up.
  const Camera proj = support::look_at_camera("proj0", {2.5, 2.4, 2.0}, {0, 1, 0}, Eigen::Vector3d::UnitY(),
                                       480, 360, 420);
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, 0, -1), Eigen::Vector3d(1, 2, 1));
  ViewpointOptions o;
  o.cut.threads = 2;
  auto cut = viewpoint_cut(proj, box, views, o);
  ASSERT_TRUE(cut) << cut.error().message;
  const RunMask truth = testing::render_mask(proj, scene);
  EXPECT_GT(support::iou(cut->coverage, truth), 0.9);
  // The true actor is covered (hull contains the object) and the near depth is never behind the
  // true surface.
  const Eigen::Vector3d C = proj.centre_in_world();
  int covered = 0, total = 0, depth_ok = 0;
  for (int y = 0; y < truth.height(); y += 3)
    for (int x = 0; x < truth.width(); x += 3) {
      if (!truth.contains(x, y)) continue;
      ++total;
      covered += cut->coverage.contains(x, y);
      const auto iv = cut->at(x, y);
      if (iv.empty()) continue;
      const Eigen::Vector3d d = proj.pixel_ray_in_world(Eigen::Vector2d(x, y));
      // March the true surface along the ray.
      double t = 0;
      while (t < 10 && !scene.inside(C + t * d)) t += 0.002;
      depth_ok += iv.front().lo <= t + 0.02;
    }
  EXPECT_GE(covered, int(0.995 * total));
  EXPECT_GE(depth_ok, int(0.995 * covered));
  // Sub-sampling gives the same mask at lower resolution.
  o.step = 4;
  auto coarse = viewpoint_cut(proj, box, views, o);
  ASSERT_TRUE(coarse);
  EXPECT_EQ(coarse->width, 120);
  EXPECT_NEAR(double(coarse->coverage.area()) * 16 / double(cut->coverage.area()), 1.0, 0.1);
}

}  // namespace
}  // namespace studio::hull

// The overlays' geometry (preview/overlays.h): frusta where the camera model puts them, the
// switches, the --overlays list.
#include "preview/overlays.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/cameras.h"

namespace studio::preview {
namespace {

Camera test_camera() {
  return support::look_at_camera("cam0", {2.0, 1.5, 3.0}, {0, 1, 0}, Eigen::Vector3d::UnitY(), 352,
                                 288, 400);
}

Projector test_projector() {
  Projector p;
  p.camera = support::look_at_camera("proj0", {0, 1.5, 3.5}, {0, 1.5, -2}, Eigen::Vector3d::UnitY(),
                                     1280, 720, 1100);
  p.screen = {Eigen::Vector3d(-1.5, 0.5, -2), Eigen::Vector3d(1.5, 0.5, -2),
              Eigen::Vector3d(1.5, 2.5, -2), Eigen::Vector3d(-1.5, 2.5, -2)};
  return p;
}

TEST(Overlays, CameraFrustumReachesTheImageCornersAtItsDepth) {
  const Camera c = test_camera();
  const auto s = camera_frustum(c, 0.7);
  ASSERT_EQ(s.size(), 10u);
  const std::array<Eigen::Vector2d, 4> corners = {
      Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(351.5, -0.5), Eigen::Vector2d(351.5, 287.5),
      Eigen::Vector2d(-0.5, 287.5)};
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT((s[k].a.cast<double>() - c.centre_in_world()).norm(), 1e-5);
    Eigen::Vector2d px;
    ASSERT_TRUE(c.project(s[k].b.cast<double>(), &px));
    EXPECT_LT((px - corners[k]).norm(), 0.05) << k;
    const Eigen::Vector3d in_cam = c.cam_from_world * s[k].b.cast<double>();
    EXPECT_NEAR(in_cam.z(), 0.7, 1e-5);
    // The cut's rectangle joins consecutive corners.
    EXPECT_LT((s[4 + k].a - s[k].b).norm(), 1e-6);
    EXPECT_LT((s[4 + k].b - s[(k + 1) % 4].b).norm(), 1e-6);
  }
  // The up tick sits above the image's top edge (image y < 0).
  Eigen::Vector2d apex;
  ASSERT_TRUE(c.project(s[8].b.cast<double>(), &apex));
  EXPECT_LT(apex.y(), -0.5);
  EXPECT_EQ(s[0].colour, overlay_colour::camera);
}

TEST(Overlays, ProjectorFrustumRunsFromItsCentreToTheScreenCorners) {
  const Projector p = test_projector();
  const auto s = projector_frustum(p);
  ASSERT_EQ(s.size(), 8u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT((s[k].a.cast<double>() - p.camera.centre_in_world()).norm(), 1e-5);
    EXPECT_LT((s[k].b.cast<double>() - p.screen[k]).norm(), 1e-5);
    EXPECT_LT((s[4 + k].b.cast<double>() - p.screen[(k + 1) % 4]).norm(), 1e-5);
  }
}

TEST(Overlays, SwitchesSelectWhatIsBuilt) {
  const std::vector<Camera> cams = {test_camera()};
  const std::vector<Projector> projs = {test_projector()};
  const std::vector<HeadMarker> heads = {{"actor0", {0.1, 1.6, 0.2}, {0.4, 0, 0}, 0.9}};
  OverlayOptions all;
  const auto g = build_overlays(all, cams, projs, heads);
  // 10 camera + 8 projector + velocity + 1 sight line to the projector's screen.
  EXPECT_EQ(g.lines.size(), 20u);
  ASSERT_EQ(g.spheres.size(), 1u);
  EXPECT_LT((g.spheres[0].centre - Eigen::Vector3f(0.1f, 1.6f, 0.2f)).norm(), 1e-6);
  ASSERT_EQ(g.screens.size(), 1u);
  EXPECT_EQ(g.screens[0].projector_id, "proj0");
  const OverlaySegment& velocity = g.lines[18];
  EXPECT_EQ(velocity.colour, overlay_colour::velocity);
  EXPECT_LT((velocity.b - Eigen::Vector3f(0.3f, 1.6f, 0.2f)).norm(), 1e-6);  // 0.5 s ahead

  OverlayOptions none;
  ASSERT_TRUE(parse_overlay_list("none", none));
  const auto empty = build_overlays(none, cams, projs, heads);
  EXPECT_TRUE(empty.lines.empty() && empty.spheres.empty() && empty.screens.empty());

  OverlayOptions screens_only;
  ASSERT_TRUE(parse_overlay_list("screens", screens_only));
  const auto s = build_overlays(screens_only, cams, projs, heads);
  EXPECT_TRUE(s.lines.empty() && s.spheres.empty());
  EXPECT_EQ(s.screens.size(), 1u);

  // A non-finite head is left out, not drawn at NaN.
  const std::vector<HeadMarker> bad = {{"a", {std::nan(""), 1, 0}, {0, 0, 0}, 1}};
  EXPECT_TRUE(build_overlays(all, {}, {}, bad).spheres.empty());
}

TEST(Overlays, ListAndOptionsRefuseNonsense) {
  OverlayOptions o;
  ASSERT_TRUE(parse_overlay_list("head,projectors", o));
  EXPECT_TRUE(o.head && o.projector_frusta);
  EXPECT_FALSE(o.camera_frusta || o.projector_screens);
  ASSERT_TRUE(parse_overlay_list("all", o));
  EXPECT_TRUE(o.head && o.camera_frusta && o.projector_frusta && o.projector_screens);
  const auto bad = parse_overlay_list("head,frusta", o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("'frusta'"), std::string::npos);
  EXPECT_TRUE(o.head && o.camera_frusta);  // untouched by the refused list

  EXPECT_TRUE(OverlayOptions{}.validate());
  OverlayOptions neg;
  neg.camera_frustum_m = -1;
  EXPECT_FALSE(neg.validate());
  OverlayOptions huge;
  huge.head_radius_m = 5;
  EXPECT_FALSE(huge.validate());
}

}  // namespace
}  // namespace studio::preview

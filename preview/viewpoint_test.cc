#include "preview/viewpoint.h"

#include <gtest/gtest.h>

#include <numbers>

namespace studio::preview {
namespace {

TEST(Viewpoint, ParsesAndPrintsTheCommandLineForm) {
  auto v = parse_viewpoint("eye=1,2,3,at=0,1,0,fov=40");
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_EQ(v->eye, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(v->at, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(v->fov_deg, 40);
  auto again = parse_viewpoint(to_string(*v));
  ASSERT_TRUE(again);
  EXPECT_TRUE(again->eye.isApprox(v->eye));
  EXPECT_EQ(parse_viewpoint("eye=0,0,5,at=0,0,0")->fov_deg, 50);  // default fov
}

TEST(Viewpoint, RefusesBadText) {
  for (const char* bad :
       {"", "eye=1,2,at=0,0,0", "eye=1,2,3,at=1,2,3", "eye=1,2,3,at=0,0,0,fov=0",
        "eye=1,x,3,at=0,0,0", "look=1,2,3", "eye=0,5,0,at=0,0,0", "eye=1,2,3,at=0,0,0,eye=1,1,1"}) {
    auto v = parse_viewpoint(bad);
    EXPECT_FALSE(v) << bad;
    if (!v) {
      EXPECT_NE(v.error().message.find("viewpoint"), std::string::npos);
    }
  }
}

TEST(Orbit, RoundTripsAViewpointAndRotatesAboutTheTarget) {
  const Viewpoint v{{3, 2, 4}, {0, 1, 0}, 45};
  Orbit o = Orbit::from(v);
  EXPECT_TRUE(o.viewpoint().eye.isApprox(v.eye, 1e-12));
  const double d = (v.eye - v.at).norm();
  o.rotate(0.7, 0.1);
  EXPECT_NEAR((o.viewpoint().eye - v.at).norm(), d, 1e-12);  // stays on the sphere
  o.rotate(0, 10);                                           // clamped below the zenith
  EXPECT_LT(o.pitch, 85 * std::numbers::pi / 180 + 1e-12);
  EXPECT_TRUE(o.viewpoint().validate());
  o.zoom(1e-6);
  EXPECT_DOUBLE_EQ(o.distance, 0.2);
}

TEST(Fly, MovesEyeAndTargetTogetherInTheViewFrame) {
  const Viewpoint v{{0, 1, 5}, {0, 1, 0}, 50};
  const Viewpoint f = fly(v, {0, 0, 1});  // one metre forward (towards -z)
  EXPECT_TRUE(f.eye.isApprox(Eigen::Vector3d(0, 1, 4)));
  EXPECT_TRUE(f.at.isApprox(Eigen::Vector3d(0, 1, -1)));
  const Viewpoint r = fly(v, {1, 0, 0});  // right of a camera looking along -z is +x
  EXPECT_TRUE(r.eye.isApprox(Eigen::Vector3d(1, 1, 5)));
  const Viewpoint t = turn(v, 0.1, 0);
  EXPECT_TRUE(t.eye.isApprox(v.eye));
  EXPECT_NEAR((t.at - t.eye).norm(), 5, 1e-9);
}

TEST(Bookmarks, KeepNamedViews) {
  Bookmarks b;
  b.set("wide", {{0, 2, 8}, {0, 1, 0}, 60});
  ASSERT_NE(b.find("wide"), nullptr);
  EXPECT_EQ(b.find("wide")->fov_deg, 60);
  EXPECT_EQ(b.find("close"), nullptr);
  EXPECT_TRUE(b.remove("wide"));
  EXPECT_FALSE(b.remove("wide"));
}

TEST(CameraMove, PassesThroughItsKeysAndHoldsOutside) {
  const Viewpoint a{{0, 1, 5}, {0, 1, 0}, 50}, b{{5, 1, 0}, {0, 1, 0}, 30},
      c{{0, 1, -5}, {0, 1, 0}, 50};
  auto m = CameraMove::create({{0, a}, {2, b}, {4, c}});
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->at(-1).eye.isApprox(a.eye));
  EXPECT_TRUE(m->at(2).eye.isApprox(b.eye));
  EXPECT_TRUE(m->at(9).eye.isApprox(c.eye));
  EXPECT_NEAR(m->at(1).fov_deg, 40, 1e-12);
  EXPECT_DOUBLE_EQ(m->duration(), 4);
  // Smooth through the middle key: the velocity just before and after it agree.
  const double h = 1e-4;
  const Eigen::Vector3d before = (m->at(2).eye - m->at(2 - h).eye) / h;
  const Eigen::Vector3d after = (m->at(2 + h).eye - m->at(2).eye) / h;
  EXPECT_LT((before - after).norm(), 1e-2);
}

TEST(CameraMove, RefusesBadKeys) {
  const Viewpoint a{{0, 1, 5}, {0, 1, 0}, 50};
  EXPECT_FALSE(CameraMove::create({}));
  EXPECT_FALSE(CameraMove::create({{1, a}, {1, a}}));
  EXPECT_FALSE(CameraMove::create({{0, a}, {1, Viewpoint{{0, 1, 0}, {0, 1, 0}, 50}}}));
}

}  // namespace
}  // namespace studio::preview

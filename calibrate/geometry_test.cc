#include <gtest/gtest.h>

#include "calibrate/bundle.h"
#include "calibrate/geometry.h"
#include "calibrate/pose_graph.h"

namespace studio::calibrate {
namespace {

Camera test_camera(const Eigen::Vector3d& centre, double yaw) {
  Camera c;
  c.id = "c";
  c.width = 640;
  c.height = 480;
  c.intrinsics = Intrinsics{600, 610, 320, 240, 0};
  c.distortion = Distortion::radial(-0.1, 0.02);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.cam_from_world = Rigid3(Eigen::Matrix3d(r.transpose()), -(r.transpose() * centre));
  return c;
}

TEST(Geometry, HomographyIsExactOnExactData) {
  Eigen::Matrix3d h;
  h << 500, 20, 300, -10, 480, 200, 0.1, 0.05, 1;
  std::vector<Eigen::Vector2d> xy, px;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j) {
      xy.emplace_back(i * 0.1, j * 0.1);
      px.push_back((h * xy.back().homogeneous()).hnormalized());
    }
  auto fit = fit_homography(xy, px);
  ASSERT_TRUE(fit);
  EXPECT_LT((*fit - h).norm() / h.norm(), 1e-9);
  std::vector<Eigen::Vector2d> line(6, Eigen::Vector2d::Zero());
  for (int i = 0; i < 6; ++i) line[i] = Eigen::Vector2d(i, 2 * i);
  EXPECT_FALSE(fit_homography(line, line));
}

TEST(Geometry, ZhangFocalFromTiltedViews) {
  Camera cam = test_camera(Eigen::Vector3d::Zero(), 0);
  cam.distortion = Distortion::none();
  std::vector<Eigen::Matrix3d> hs;
  for (double tilt : {0.3, -0.4, 0.5}) {
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(0.7 * tilt, Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    Eigen::Matrix3d m;
    m << r.col(0), r.col(1), Eigen::Vector3d(-0.2, -0.1, 2.0);
    hs.push_back(cam.intrinsics.K() * m);
  }
  auto f = focal_from_homographies(hs, 320, 240);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_NEAR(f->x(), 600, 1e-6);
  EXPECT_NEAR(f->y(), 610, 1e-6);
}

TEST(Geometry, PlanarPoseAndTriangulationInvertProjection) {
  const Camera a = test_camera(Eigen::Vector3d(-0.5, 0, -3), 0.15);
  const Camera b = test_camera(Eigen::Vector3d(0.6, 0.1, -3), -0.2);
  const Rigid3 world_from_target(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized())),
                                 Eigen::Vector3d(-0.2, -0.2, 0.3));
  std::vector<Eigen::Vector3d> target;
  std::vector<Eigen::Vector2d> pa;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 5; ++j) {
      target.emplace_back(i * 0.08, j * 0.08, 0);
      Eigen::Vector2d p, q;
      const Eigen::Vector3d x = world_from_target * target.back();
      ASSERT_TRUE(a.project(x, &p));
      ASSERT_TRUE(b.project(x, &q));
      pa.push_back(p);
      auto t = triangulate({a, b}, {p, q});
      ASSERT_TRUE(t) << t.error().message;
      EXPECT_LT((*t - x).norm(), 1e-9);
    }
  auto pose = planar_pose(a, target, pa);
  ASSERT_TRUE(pose) << pose.error().message;
  const Rigid3 expect = a.cam_from_world * world_from_target;
  EXPECT_LT((pose->translation - expect.translation).norm(), 1e-9);
  EXPECT_LT(pose->rotation.angularDistance(expect.rotation), 1e-9);
  EXPECT_FALSE(triangulate({a, a}, {pa[0], pa[0]}));
}

TEST(Geometry, FloorParameterisationRoundTrips) {
  const Rigid3 p = floor_pose(0.7, 1.5, -2.0);
  EXPECT_LT((p.rotation * Eigen::Vector3d::UnitZ() + Eigen::Vector3d::UnitY()).norm(), 1e-12);
  const Eigen::Vector3d back = floor_parameters(p);
  EXPECT_NEAR(back.x(), 0.7, 1e-12);
  EXPECT_NEAR(back.y(), 1.5, 1e-12);
  EXPECT_NEAR(back.z(), -2.0, 1e-12);
  EXPECT_LT((floor_pose(0, 0, 0) * Eigen::Vector3d(1, 2, 0) - Eigen::Vector3d(1, 0, 2)).norm(), 1e-12);
}

TEST(PoseGraph, ChainsThroughSharedFramesAndReportsIslands) {
  // sensors 0,1 share frame 0; sensor 1,2 share frame 1; sensor 3 only sees frame 2.
  const Rigid3 s0(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())), Eigen::Vector3d(1, 0, 0));
  const Rigid3 s1(Eigen::Quaterniond(Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitX())), Eigen::Vector3d(0, 1, 0));
  const Rigid3 s2(Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(0, 0, 2));
  const Rigid3 f0(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 3));
  const Rigid3 f1(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())), Eigen::Vector3d(1, 0, 3));
  std::vector<PoseEdge> edges = {{0, 0, s0 * f0, 10}, {1, 0, s1 * f0, 10}, {1, 1, s1 * f1, 5},
                                 {2, 1, s2 * f1, 5}, {3, 2, Rigid3::identity(), 50}};
  const ChainedPoses c = chain_poses(4, 3, edges, {false, 0, s0});
  ASSERT_TRUE(c.sensor_from_world[2]);
  EXPECT_LT((c.sensor_from_world[2]->translation - s2.translation).norm(), 1e-12);
  EXPECT_EQ(c.unreached_sensors(), std::vector<int>{3});
  EXPECT_EQ(c.unreached_frames(), std::vector<int>{2});
}

}  // namespace
}  // namespace studio::calibrate

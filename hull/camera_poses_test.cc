// The hull's cameras by frame (hull/camera_poses.h): a tracked camera's frame N is cut with its
// pose of frame N even when N+1's has arrived; fixed cameras are replaced; the history is bounded.
#include "hull/camera_poses.h"

#include <gtest/gtest.h>

namespace studio::hull {
namespace {

// A camera told apart by its id and its x translation (the pose of `frame`).
Camera camera(const std::string& id, double x) {
  Camera c;
  c.id = id;
  c.width = 64;
  c.height = 48;
  c.cam_from_world.translation = Eigen::Vector3d(x, 0, 4);
  return c;
}
double x_of(const CameraPoses::Pose& p) { return p.camera->cam_from_world.translation.x(); }

TEST(CameraPoses, FixedCameraIsReplacedAndNeverStale) {
  CameraPoses poses({camera("a", 0), camera("b", 1)});
  EXPECT_EQ(poses.size(), 2u);
  EXPECT_EQ(x_of(poses.camera_for(1, 100)), 1);
  EXPECT_FALSE(poses.camera_for(1, 100).stale);
  poses.update(1, 5, false, camera("b", 7));
  EXPECT_EQ(x_of(poses.camera_for(1, 3)), 7);  // a fixed camera has no frames: the latest
  EXPECT_FALSE(poses.camera_for(1, 3).stale);
  EXPECT_EQ(poses.latest(1).cam_from_world.translation.x(), 7);
  EXPECT_EQ(x_of(poses.camera_for(0, 3)), 0);  // the other camera is untouched
}

TEST(CameraPoses, TrackedCameraIsCutWithThePoseOfItsFrame) {
  CameraPoses poses({camera("a", 0)});
  // Frames 10..12 arrive out of order, 11 twice (the second replaces the first).
  poses.update(0, 12, true, camera("a", 12));
  poses.update(0, 10, true, camera("a", 10));
  poses.update(0, 11, true, camera("a", 99));
  poses.update(0, 11, true, camera("a", 11));
  for (uint64_t f : {10, 11, 12}) {
    const auto p = poses.camera_for(0, f);
    EXPECT_EQ(x_of(p), double(f));
    EXPECT_FALSE(p.stale) << f;
  }
  // A frame without its own pose: the latest before it, stale.
  auto p = poses.camera_for(0, 15);
  EXPECT_EQ(x_of(p), 12);
  EXPECT_TRUE(p.stale);
  // Older than every kept pose: the oldest kept, stale.
  p = poses.camera_for(0, 3);
  EXPECT_EQ(x_of(p), 10);
  EXPECT_TRUE(p.stale);
  // The latest calibration is the last one received.
  EXPECT_EQ(poses.latest(0).cam_from_world.translation.x(), 11);
  // A fixed calibration ends the tracked history.
  poses.update(0, 20, false, camera("a", 50));
  p = poses.camera_for(0, 11);
  EXPECT_EQ(x_of(p), 50);
  EXPECT_FALSE(p.stale);
}

TEST(CameraPoses, HistoryIsBounded) {
  CameraPoses poses({camera("a", 0)}, 4);
  for (uint64_t f = 1; f <= 10; ++f) poses.update(0, f, true, camera("a", double(f)));
  EXPECT_EQ(x_of(poses.camera_for(0, 7)), 7);
  EXPECT_FALSE(poses.camera_for(0, 7).stale);
  // Frames 1..6 were forgotten: the oldest kept (7) answers, stale.
  EXPECT_EQ(x_of(poses.camera_for(0, 2)), 7);
  EXPECT_TRUE(poses.camera_for(0, 2).stale);
}

}  // namespace
}  // namespace studio::hull

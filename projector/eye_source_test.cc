// The projector's eye (projector/eye_source.h): the head while fresh, the last good eye after it
// times out (reported once), the default eye before any head.
#include <gtest/gtest.h>

#include "projector/eye_source.h"

namespace studio::projector {
namespace {

TEST(EyeSource, FreshHeadElseLastGoodEye) {
  EyeSource e({0, 1.7, 2}, 2.0);
  bool stale = true;
  EXPECT_EQ(e.eye(0.0, &stale), Eigen::Vector3d(0, 1.7, 2));
  EXPECT_FALSE(stale);
  e.head({0.1, 1.6, 1.2}, 1.0);
  EXPECT_EQ(e.eye(2.5, &stale), Eigen::Vector3d(0.1, 1.6, 1.2));
  e.good({0.1, 1.6, 1.2});
  EXPECT_EQ(e.eye(3.5, &stale), Eigen::Vector3d(0.1, 1.6, 1.2));  // timed out: last good eye
  EXPECT_TRUE(stale);
  EXPECT_EQ(e.eye(4.0, &stale), Eigen::Vector3d(0.1, 1.6, 1.2));
  EXPECT_FALSE(stale);  // reported once
  e.head({0, 1.6, -4}, 5.0);  // an eye the projection refuses: the caller keeps the last good
  EXPECT_EQ(e.eye(5.1), Eigen::Vector3d(0, 1.6, -4));
  EXPECT_EQ(e.last_good(), Eigen::Vector3d(0.1, 1.6, 1.2));
}

}  // namespace
}  // namespace studio::projector

#include "hull/segment_set.h"

#include <gtest/gtest.h>

namespace studio::hull {
namespace {

TEST(SegmentSet, FullEmptyAndVolume) {
  GridSpec g;
  g.box_min = {0, 0, 0};
  g.box_max = {2, 3, 4};
  g.axis = Axis::y;
  g.cells_u = 4;  // along z
  g.cells_v = 2;  // along x
  ASSERT_TRUE(g.validate());
  EXPECT_EQ(g.u(), 2);
  EXPECT_EQ(g.v(), 0);
  const SegmentSet full = SegmentSet::full(g);
  EXPECT_TRUE(full.valid());
  EXPECT_NEAR(full.volume(), 24.0, 1e-9);
  EXPECT_TRUE(full.contains({1, 1, 1}));
  EXPECT_FALSE(full.contains({1, 3.5, 1}));
  EXPECT_NEAR(SegmentSet::empty(g).volume(), 0.0, 0.0);
  EXPECT_TRUE(g.point(0, 0, 1.5).isApprox(Eigen::Vector3d(0.5, 1.5, 0.5)));
}

TEST(SegmentSet, ValidateRejectsEmptyBoxAndBadGrid) {
  GridSpec g;
  g.box_max = {1, 0, 1};
  auto r = g.validate();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("empty along y"), std::string::npos);
  g.box_max = {1, 1, 1};
  g.cells_u = 0;
  EXPECT_FALSE(g.validate());
}

TEST(SegmentSet, FromColumnsMergesTouchingAndComponentsSplit) {
  GridSpec g;
  g.cells_u = 3;
  g.cells_v = 1;
  std::vector<std::vector<Interval>> cols(3);
  cols[0] = {{0.1f, 0.2f}, {0.2f, 0.3f}, {0.5f, 0.6f}};
  cols[1] = {{0.25f, 0.4f}};
  cols[2] = {{0.3f, 0.35f}};
  const SegmentSet s = SegmentSet::from_columns(g, cols);
  ASSERT_TRUE(s.valid());
  EXPECT_EQ(s.column(0, 0).size(), 2u);
  const auto parts = connected_components(s);
  ASSERT_EQ(parts.size(), 2u);  // {col0[0], col1, col2} and {col0[1]}
  EXPECT_EQ(parts[0].interval_count(), 3u);
  EXPECT_NEAR(parts[0].volume() + parts[1].volume(), s.volume(), 1e-6);
}

}  // namespace
}  // namespace studio::hull

#include "tracker/head_search.h"

#include <gtest/gtest.h>

#include "testing/synthetic_actor.h"

namespace studio::tracker {
namespace {

using testing::add_actor;
using testing::SyntheticActor;

OccupancyGrid studio_grid(int columns = 128) {
  return make_grid({-1.5, 0, -1.5}, {1.5, 2.4, 1.5}, columns);
}

HeadSearch search(HeadSearchOptions o = {}) { return HeadSearch::create(o).value(); }

TEST(HeadSearch, FindsTheHeadOfAStandingActorWithinACentimetre) {
  OccupancyGrid g = studio_grid();
  SyntheticActor a;
  a.floor_xz = {0.3, -0.4};
  add_actor(g, a);
  auto s = search();
  const auto heads = s.find(g);
  ASSERT_EQ(heads.size(), 1u);
  EXPECT_LT((heads[0].position - a.head_centre()).norm(), 0.01) << heads[0].position.transpose();
  EXPECT_GT(heads[0].confidence, 0.6);
  EXPECT_LE(heads[0].confidence, 1.0);
}

TEST(HeadSearch, NeverLocksOntoARaisedHand) {
  for (double yaw : {0.0, 0.8, 1.6, 2.4}) {
    OccupancyGrid g = studio_grid();
    SyntheticActor a;
    a.hand_raised = true;
    a.yaw = yaw;
    add_actor(g, a);
    auto s = search();
    const auto heads = s.find(g);
    ASSERT_EQ(heads.size(), 1u) << "one head per actor, yaw " << yaw;
    EXPECT_LT((heads[0].position - a.head_centre()).norm(), 0.02) << "yaw " << yaw;
    EXPECT_GT((heads[0].position - a.raised_hand_centre()).norm(), 0.25);
  }
}

TEST(HeadSearch, FollowsACrouchingActor) {
  for (double crouch : {0.3, 0.6, 1.0}) {
    OccupancyGrid g = studio_grid();
    SyntheticActor a;
    a.crouch = crouch;
    add_actor(g, a);
    auto s = search();
    const auto heads = s.find(g);
    ASSERT_EQ(heads.size(), 1u);
    EXPECT_LT((heads[0].position - a.head_centre()).norm(), 0.015) << "crouch " << crouch;
  }
}

TEST(HeadSearch, FindsOneHeadPerActorInScoreOrder) {
  OccupancyGrid g = studio_grid();
  SyntheticActor a, b, c;
  a.floor_xz = {-0.8, 0.5};
  b.floor_xz = {0.6, 0.4};
  b.hand_raised = true;
  c.floor_xz = {0.2, -0.9};
  c.crouch = 0.5;
  c.height = 1.6;
  for (const auto& x : {a, b, c}) add_actor(g, x);
  auto s = search();
  const auto heads = s.find(g);
  ASSERT_EQ(heads.size(), 3u);
  for (const auto& x : {a, b, c}) {
    int near = 0;
    for (const auto& h : heads) near += (h.position - x.head_centre()).norm() < 0.02;
    EXPECT_EQ(near, 1) << x.head_centre().transpose();
  }
  for (std::size_t i = 1; i < heads.size(); ++i) EXPECT_GE(heads[i - 1].score, heads[i].score);
}

TEST(HeadSearch, BranchAndBoundEqualsTheExhaustiveSearch) {
  // Several scenes, two grid resolutions, with and without the region under the head.
  for (int columns : {48, 96}) {
    for (bool below : {true, false}) {
      OccupancyGrid g = studio_grid(columns);
      SyntheticActor a, b;
      a.floor_xz = {-0.5, 0.2};
      a.hand_raised = true;
      b.floor_xz = {0.7, -0.3};
      b.crouch = 0.4;
      add_actor(g, a);
      add_actor(g, b);
      testing::add_sphere(g, {0.0, 0.3, 1.0}, 0.15);  // a ball on the floor
      HeadSearchOptions o;
      o.exclude_below = below;
      o.min_confidence = 0.05;
      o.max_heads = 6;
      auto s = search(o);
      const auto fast = s.find(g);
      const int64_t fast_bounds = s.stats().bounds;
      const auto slow = s.find_exhaustive(g);
      ASSERT_EQ(fast.size(), slow.size()) << columns << " " << below;
      for (std::size_t i = 0; i < fast.size(); ++i) {
        EXPECT_EQ(fast[i].score, slow[i].score);
        EXPECT_EQ(fast[i].box_min, slow[i].box_min);
        EXPECT_EQ(fast[i].position, slow[i].position);
      }
      EXPECT_LT(fast_bounds * 20, s.stats().bounds) << "branch and bound should prune";
    }
  }
}

TEST(HeadSearch, TheSameHeadOnACroppedGrid) {
  OccupancyGrid g = studio_grid();
  SyntheticActor a;
  a.hand_raised = true;
  add_actor(g, a);
  auto s = search();
  const auto full = s.find(g);
  const auto cropped = s.find(g.cropped_to_occupied());
  ASSERT_EQ(full.size(), 1u);
  ASSERT_EQ(cropped.size(), 1u);
  EXPECT_NEAR((full[0].position - cropped[0].position).norm(), 0, 1e-9);
  EXPECT_EQ(full[0].score, cropped[0].score);
}

TEST(HeadSearch, EmptyOrHeadlessVolumesGiveNoHead) {
  auto s = search();
  EXPECT_TRUE(s.find(studio_grid()).empty());
  EXPECT_TRUE(s.find(OccupancyGrid()).empty());
  OccupancyGrid slab = studio_grid(64);
  testing::add_box(slab, {-1.5, 0, -1.5}, {1.5, 0.3, 1.5});  // a floor slab: no head anywhere
  EXPECT_TRUE(s.find(slab).empty());
  EXPECT_TRUE(s.find_exhaustive(slab).empty());
}

TEST(HeadSearch, ExcludingTheRegionUnderTheHeadRaisesItsScore) {
  OccupancyGrid g = studio_grid();
  add_actor(g, SyntheticActor{});
  HeadSearchOptions with, without;
  with.outer_box.y() = without.outer_box.y() = 0.34;  // V1 reaches 5 cm above and below V2
  without.exclude_below = false;
  without.min_confidence = 0.01;
  const auto a = search(with).find(g);
  const auto b = search(without).find(g);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_GT(a[0].score, b[0].score);
}

TEST(HeadSearchOptions, RejectsNonsense) {
  HeadSearchOptions o;
  o.outer_box = {0.1, 0.5, 0.5};
  EXPECT_FALSE(o.validate());
  o = {};
  o.head_box.y() = 0;
  EXPECT_FALSE(HeadSearch::create(o).has_value());
  o = {};
  o.min_confidence = 0;
  EXPECT_FALSE(o.validate());
  o = {};
  o.max_heads = 0;
  EXPECT_FALSE(o.validate());
  EXPECT_TRUE(HeadSearchOptions{}.validate());
}

}  // namespace
}  // namespace studio::tracker

// Actor-topic conversions: SegmentSet and HeadPose round trips through the wire types, the wire
// validator accepts what from_core writes, and to_core turns malformed payloads into one line.
#include "wire/actor_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "wire/sample.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

hull::SegmentSet sample_set(hull::Axis axis) {
  hull::GridSpec g;
  g.box_min = {-1.5, 0, -1.25};
  g.box_max = {1.5, 2.5, 1.75};
  g.axis = axis;
  g.cells_u = 5;
  g.cells_v = 3;
  std::vector<std::vector<hull::Interval>> cols(g.columns());
  const float lo = float(g.t_min()), hi = float(g.t_max());
  cols[0] = {{lo, lo + 0.5f}, {lo + 0.75f, hi}};
  cols[7] = {{lo + 0.125f, lo + 0.25f}};
  cols[14] = {{lo, hi}};
  return hull::SegmentSet::from_columns(g, cols);
}

TEST(SegmentsWire, RoundTripOnEveryAxisPassesTheValidator) {
  for (auto axis : {hull::Axis::x, hull::Axis::y, hull::Axis::z}) {
    const hull::SegmentSet segments = sample_set(axis);
    Owned<studio_SegmentSet> s;
    set(s->actor_id, "actor");
    from_core(segments, *s);
    EXPECT_FALSE(validate(*s).has_value());
    EXPECT_EQ(s->nu, 5u);
    EXPECT_EQ(s->nv, 3u);
    EXPECT_EQ(s->axis, uint8_t(axis));
    auto back = to_core(*s);
    ASSERT_TRUE(back.has_value()) << back.error().message;
    EXPECT_TRUE(back->valid());
    EXPECT_EQ(back->grid(), segments.grid());  // these box corners are exact in float
    EXPECT_EQ(back->intervals(), segments.intervals());
    EXPECT_EQ(back->start(), segments.start());
    EXPECT_DOUBLE_EQ(back->volume(), segments.volume());
  }
}

TEST(SegmentsWire, EmptyHullRoundTrips) {
  hull::GridSpec g;
  g.cells_u = g.cells_v = 16;
  Owned<studio_SegmentSet> s;
  set(s->actor_id, "actor");
  from_core(hull::SegmentSet::empty(g), *s);
  EXPECT_FALSE(validate(*s).has_value());
  auto back = to_core(*s);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->interval_count(), 0u);
  EXPECT_EQ(back->start().size(), 257u);
}

TEST(SegmentsWire, ZeroLengthDroppedAndTouchingMerged) {
  Owned<studio_SegmentSet> s;
  set(s->actor_id, "actor");
  s->nu = 2;
  s->nv = 1;
  for (int k = 0; k < 3; ++k) {
    s->box_min[k] = 0;
    s->box_max[k] = 2;
  }
  s->axis = 1;
  assign(s->interval_start, std::vector<uint32_t>{0, 3, 4});
  assign(s->intervals, std::vector<float>{0.0f, 0.5f, 0.5f, 1.0f, 1.5f, 1.5f, 0.25f, 0.25f});
  ASSERT_FALSE(validate(*s).has_value());  // the wire allows both
  auto set = to_core(*s);
  ASSERT_TRUE(set.has_value()) << set.error().message;
  EXPECT_TRUE(set->valid());
  ASSERT_EQ(set->interval_count(), 1u);
  EXPECT_EQ(set->intervals()[0], (hull::Interval{0.0f, 1.0f}));
  EXPECT_TRUE(set->column(1).empty());
}

TEST(SegmentsWire, MalformedPayloadsGiveOneLine) {
  auto base = [] {
    Owned<studio_SegmentSet> s;
    set(s->actor_id, "a1");
    s->nu = s->nv = 1;
    for (int k = 0; k < 3; ++k) s->box_max[k] = 1;
    s->axis = 1;
    assign(s->interval_start, std::vector<uint32_t>{0, 1});
    assign(s->intervals, std::vector<float>{0.25f, 0.75f});
    return s;
  };
  ASSERT_TRUE(to_core(*base()).has_value());
  auto expect_fail = [](const studio_SegmentSet& s, const char* what) {
    auto r = to_core(s);
    ASSERT_FALSE(r.has_value()) << what;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    EXPECT_NE(r.error().message.find("segments a1"), std::string::npos) << r.error().message;
  };
  {
    auto s = base();
    s->axis = 3;
    expect_fail(*s, "axis");
  }
  {
    auto s = base();
    s->box_max[0] = 0;
    expect_fail(*s, "empty box");
  }
  {
    auto s = base();
    s->nu = 2;
    expect_fail(*s, "table size");
  }
  {
    auto s = base();
    assign(s->intervals, std::vector<float>{0.75f, 0.25f});
    expect_fail(*s, "reversed");
  }
  {
    auto s = base();
    assign(s->intervals, std::vector<float>{0.25f, 1.5f});
    expect_fail(*s, "outside the box");
  }
  {
    auto s = base();
    assign(s->interval_start, std::vector<uint32_t>{0, 2});
    assign(s->intervals, std::vector<float>{0.5f, 0.75f, 0.25f, 0.375f});
    expect_fail(*s, "unsorted");
  }
  {
    auto s = base();
    assign(s->intervals, std::vector<float>{std::numeric_limits<float>::quiet_NaN(), 0.5f});
    expect_fail(*s, "NaN");
  }
}

TEST(HeadWire, RoundTripAndRejects) {
  tracker::HeadPose p;
  p.position = {0.25, 1.625, -0.5};
  p.velocity = {0.5, 0, -0.125};
  p.confidence = 0.75;
  p.capture_ns = 1'700'000'000'123'456'789;
  Owned<studio_HeadPose> s;
  set(s->actor_id, "actor");
  from_core(p, *s);
  EXPECT_FALSE(validate(*s).has_value());
  auto back = to_core(*s);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->position, p.position);
  EXPECT_EQ(back->velocity, p.velocity);
  EXPECT_EQ(back->confidence, p.confidence);
  EXPECT_EQ(back->capture_ns, p.capture_ns);

  p.confidence = 1.5;  // clamped on the way out
  from_core(p, *s);
  EXPECT_EQ(s->confidence, 1.0);
  s->confidence = -0.5;
  EXPECT_FALSE(to_core(*s).has_value());
  s->confidence = 0.5;
  s->position[1] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(to_core(*s).has_value());
}

}  // namespace
}  // namespace studio::wire

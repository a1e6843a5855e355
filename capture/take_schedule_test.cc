// Frame-accurate take control: takes record exactly [start, stop), late commands are refused or
// clamped, dropped start frames are reported.
#include "capture/take_schedule.h"

#include <gtest/gtest.h>

namespace studio::capture {
namespace {

TEST(TakeSchedule, RecordsExactlyStartToStop) {
  TakeSchedule s;
  s.on_frame(100);
  ASSERT_TRUE(s.start("t", 105));
  ASSERT_EQ(s.stop("t", 110).value(), 110u);
  std::vector<uint64_t> recorded;
  bool began = false, ended = false;
  for (uint64_t f = 101; f < 120; ++f) {
    auto d = s.on_frame(f);
    if (d.begin) {
      began = true;
      EXPECT_EQ(f, 105u);
      EXPECT_EQ(d.missed, 0u);
    }
    if (d.ended) {
      ended = true;
      EXPECT_EQ(f, 110u);
      EXPECT_EQ(d.ended->name, "t");
    }
    if (d.record) recorded.push_back(f);
  }
  EXPECT_TRUE(began && ended);
  EXPECT_EQ(recorded, (std::vector<uint64_t>{105, 106, 107, 108, 109}));
  EXPECT_FALSE(s.recording());
}

TEST(TakeSchedule, RefusesPastStartAndClampsLateStop) {
  TakeSchedule s;
  s.on_frame(50);
  auto late = s.start("t", 50);
  ASSERT_FALSE(late);
  EXPECT_NE(late.error().message.find("already passed"), std::string::npos);
  ASSERT_TRUE(s.start("t", 52));
  s.on_frame(51);
  EXPECT_TRUE(s.on_frame(52).begin);
  s.on_frame(53);
  EXPECT_EQ(s.stop("t", 40).value(), 54u);  // already passed: ends at the next frame
  EXPECT_TRUE(s.on_frame(54).ended.has_value());
  EXPECT_FALSE(s.stop("nope", 60));
}

TEST(TakeSchedule, DroppedStartFrameAndOneTakeAtATime) {
  TakeSchedule s;
  s.on_frame(1);
  ASSERT_TRUE(s.start("a", 10));
  EXPECT_FALSE(s.start("b", 12));
  s.on_frame(8);
  auto d = s.on_frame(12);  // 9..11 dropped by the source
  EXPECT_TRUE(d.begin);
  EXPECT_EQ(d.missed, 2u);
  EXPECT_TRUE(d.record);
  EXPECT_FALSE(s.start("b", 20));
  ASSERT_TRUE(s.stop("a", 13));
  d = s.on_frame(13);
  ASSERT_TRUE(d.ended);
  EXPECT_FALSE(d.record);
  ASSERT_TRUE(s.start("b", 20));
  ASSERT_TRUE(s.stop("b", 25));
  EXPECT_FALSE(s.on_frame(25).begin);  // nothing delivered inside [20, 25): empty take
  EXPECT_FALSE(s.pending());
}

}  // namespace
}  // namespace studio::capture

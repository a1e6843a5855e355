#include "core/frame_assembler.h"

#include <gtest/gtest.h>

namespace studio {
namespace {

using namespace std::chrono_literals;
using Assembler = FrameAssembler<int>;
using Clock = Assembler::Clock;

Assembler make(std::size_t min_sources = 1) {
  return Assembler({.sources = {"a", "b", "c"}, .deadline = 40ms, .min_sources = min_sources, .max_pending = 4});
}

TEST(FrameAssembler, EmitsACompleteFrameWithEveryItem) {
  auto fa = make();
  const auto t = Clock::now();
  fa.add("a", 10, 1000, 1, t);
  fa.add("c", 10, 900, 3, t);
  EXPECT_FALSE(fa.pop(t).has_value());
  fa.add("b", 10, 1100, 2, t);
  auto f = fa.pop(t);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->frame, 10u);
  EXPECT_EQ(f->capture_ns, 900);  // earliest capture time
  EXPECT_EQ(f->items[0], 1);
  EXPECT_EQ(f->items[1], 2);
  EXPECT_EQ(f->items[2], 3);
  EXPECT_EQ(fa.counts().complete, 1u);
  EXPECT_EQ(fa.pending(), 0u);
}

TEST(FrameAssembler, DeadlineEmitsPartialFramesAndCountsMisses) {
  auto fa = make(2);
  const auto t = Clock::now();
  fa.add("a", 5, 0, 1, t);
  fa.add("b", 5, 0, 2, t + 5ms);
  EXPECT_FALSE(fa.pop(t + 39ms).has_value());
  ASSERT_TRUE(fa.next_deadline().has_value());
  EXPECT_EQ(*fa.next_deadline(), t + 40ms);
  auto f = fa.pop(t + 40ms);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->present(), 2u);
  EXPECT_FALSE(f->items[2].has_value());
  EXPECT_EQ(fa.counts().partial, 1u);
  EXPECT_EQ(fa.counts().missing_by_source[2], 1u);
  // Too few sources at the deadline: dropped, not emitted.
  fa.add("a", 6, 0, 1, t + 50ms);
  EXPECT_FALSE(fa.pop(t + 100ms).has_value());
  EXPECT_EQ(fa.counts().dropped, 1u);
}

TEST(FrameAssembler, NewestCompleteFrameSupersedesOlderOnes) {
  auto fa = make();
  const auto t = Clock::now();
  fa.add("a", 1, 0, 1, t);  // frame 1 never completes
  for (const char* s : {"a", "b", "c"}) fa.add(s, 2, 0, 7, t);
  fa.add("a", 3, 0, 1, t);  // frame 3 still pending
  auto f = fa.pop(t);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->frame, 2u);
  EXPECT_EQ(fa.counts().dropped, 1u);  // frame 1
  EXPECT_EQ(fa.pending(), 1u);         // frame 3 kept
  // Items for frames already done are late.
  fa.add("b", 1, 0, 1, t);
  fa.add("b", 2, 0, 1, t);
  EXPECT_EQ(fa.counts().late, 2u);
  fa.add("zz", 3, 0, 1, t);
  EXPECT_EQ(fa.counts().unknown_source, 1u);
}

TEST(FrameAssembler, BoundsPendingFrames) {
  auto fa = make();
  const auto t = Clock::now();
  for (uint64_t f = 0; f < 10; ++f) fa.add("a", f, 0, 1, t);
  EXPECT_EQ(fa.pending(), 4u);
  EXPECT_EQ(fa.counts().dropped, 6u);
  // An item older than everything pending (and older than the drops) is late.
  fa.add("b", 2, 0, 1, t);
  EXPECT_EQ(fa.pending(), 4u);
  EXPECT_EQ(fa.counts().late, 1u);
}

}  // namespace
}  // namespace studio

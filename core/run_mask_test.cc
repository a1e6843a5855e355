#include "core/run_mask.h"

#include <gtest/gtest.h>

#include <random>

namespace studio {
namespace {

TEST(RunMask, RoundTripsRandomMasks) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const int w = 1 + int(rng() % 97), h = 1 + int(rng() % 31);
    Mask m(w, h, 0);
    const double density = (rng() % 100) / 100.0;
    std::bernoulli_distribution on(density);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) m(x, y) = on(rng) ? 255 : 0;
    const RunMask r = RunMask::from_mask(m.view());
    ASSERT_TRUE(r.valid());
    EXPECT_EQ(r.to_mask().pixels(), m.pixels());
    uint64_t area = 0;
    for (uint8_t p : m.pixels()) area += p != 0;
    EXPECT_EQ(r.area(), area);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) ASSERT_EQ(r.contains(x, y), m(x, y) != 0);
  }
}

TEST(RunMask, RespectsStride) {
  // A 3x2 view into a 5-wide buffer.
  uint8_t buf[10] = {0, 255, 255, 9, 9, 255, 0, 255, 9, 9};
  const RunMask r = RunMask::from_mask(MaskView(buf, 3, 2, 5));
  ASSERT_TRUE(r.valid());
  ASSERT_EQ(r.row(0).size(), 1u);
  EXPECT_EQ(r.row(0)[0], (studio::Run{1, 3}));
  ASSERT_EQ(r.row(1).size(), 2u);
  EXPECT_EQ(r.row(1)[1], (studio::Run{2, 3}));
}

TEST(RunMask, BuilderSkipsRowsAndValidRejectsBadRuns) {
  RunMask r(10, 4);
  r.push_run(1, 2, 4);
  r.push_run(1, 6, 7);
  r.push_run(3, 0, 10);
  r.finish();
  ASSERT_TRUE(r.valid());
  EXPECT_TRUE(r.row(0).empty());
  EXPECT_EQ(r.row(1).size(), 2u);
  EXPECT_TRUE(r.row(2).empty());
  EXPECT_EQ(r.area(), 2u + 1u + 10u);

  RunMask touching(10, 1);
  touching.push_run(0, 2, 4);
  touching.push_run(0, 4, 6);  // touches the previous run: not canonical
  touching.finish();
  EXPECT_FALSE(touching.valid());

  RunMask outside(10, 1);
  outside.push_run(0, 8, 11);
  outside.finish();
  EXPECT_FALSE(outside.valid());
}

}  // namespace
}  // namespace studio

#include "keyer/cleanup.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace studio::keyer {
namespace {

// Brute-force oracle: flood fill on the full image.
Mask oracle_clean(const Mask& in, const CleanupOptions& o) {
  const int w = in.width(), h = in.height();
  Mask m = in;
  std::vector<int> comp(std::size_t(w) * h, -1);
  auto flood = [&](bool fg, bool eight, auto&& on_component) {
    std::fill(comp.begin(), comp.end(), -1);
    int id = 0;
    for (int sy = 0; sy < h; ++sy)
      for (int sx = 0; sx < w; ++sx) {
        if ((m(sx, sy) != 0) != fg || comp[sy * w + sx] >= 0) continue;
        std::vector<std::pair<int, int>> stack{{sx, sy}}, pixels;
        comp[sy * w + sx] = id;
        bool border = false;
        while (!stack.empty()) {
          auto [x, y] = stack.back();
          stack.pop_back();
          pixels.push_back({x, y});
          if (x == 0 || y == 0 || x == w - 1 || y == h - 1) border = true;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              if ((dx == 0 && dy == 0) || (!eight && dx != 0 && dy != 0)) continue;
              const int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              if ((m(nx, ny) != 0) != fg || comp[ny * w + nx] >= 0) continue;
              comp[ny * w + nx] = id;
              stack.push_back({nx, ny});
            }
        }
        on_component(pixels, border);
        ++id;
      }
  };
  std::vector<std::pair<int, int>> erase, fill;
  flood(true, true, [&](auto& px, bool) {
    if (int(px.size()) < o.min_component_area) erase.insert(erase.end(), px.begin(), px.end());
  });
  for (auto [x, y] : erase) m(x, y) = 0;
  flood(false, false, [&](auto& px, bool border) {
    if (!border && int(px.size()) <= o.max_hole_area) fill.insert(fill.end(), px.begin(), px.end());
  });
  for (auto [x, y] : fill) m(x, y) = 255;
  return m;
}

TEST(Cleanup, MatchesFloodFillOracleOnRandomMasks) {
  std::mt19937 rng(3);
  CleanupScratch scratch;
  RunMask out;
  for (int trial = 0; trial < 200; ++trial) {
    const int w = 1 + int(rng() % 40), h = 1 + int(rng() % 30);
    Mask m(w, h, 0);
    std::bernoulli_distribution on(0.2 + 0.6 * (rng() % 100) / 100.0);
    for (auto& p : m.pixels()) p = on(rng) ? 255 : 0;
    const CleanupOptions o{int(rng() % 12), int(rng() % 12)};
    const RunMask in = RunMask::from_mask(m.view());
    clean_mask(in, o, out, scratch);
    ASSERT_TRUE(out.valid());
    ASSERT_EQ(out.to_mask().pixels(), oracle_clean(m, o).pixels())
        << "trial " << trial << " " << w << "x" << h << " min " << o.min_component_area
        << " hole " << o.max_hole_area;
  }
}

TEST(Cleanup, RemovesSpecksFillsHolesKeepsOpenings) {
  Mask m(40, 30, 0);
  for (int y = 5; y < 25; ++y)
    for (int x = 5; x < 25; ++x) m(x, y) = 255;
  m(10, 10) = 0;                                  // a 1-pixel hole: filled
  for (int y = 12; y < 20; ++y)                   // a 64-pixel hole: kept with max 50
    for (int x = 14; x < 22; ++x) m(x, y) = 0;
  for (int y = 8; y < 12; ++y) m(5, y) = 0;       // a notch open to the outside: kept
  m(35, 3) = 255;                                 // a speck: removed
  RunMask out;
  CleanupScratch scratch;
  const CleanupStats stats = clean_mask(RunMask::from_mask(m.view()), {4, 50}, out, scratch);
  EXPECT_EQ(stats.components_removed, 1);
  EXPECT_EQ(stats.holes_filled, 1);
  const Mask r = out.to_mask();
  EXPECT_EQ(r(10, 10), 255);
  EXPECT_EQ(r(16, 15), 0);
  EXPECT_EQ(r(5, 9), 0);
  EXPECT_EQ(r(35, 3), 0);
  EXPECT_EQ(r(6, 6), 255);
}

// With a shows_backing test, a small hole one of whose runs shows the clean backing stays open;
// the test is asked only about runs of holes that would be filled.
TEST(Cleanup, KeepsHolesThatShowTheBacking) {
  Mask m(40, 30, 0);
  for (int y = 5; y < 25; ++y)
    for (int x = 5; x < 35; ++x) m(x, y) = 255;
  for (int y = 10; y < 14; ++y)  // hole A (x 10..13): shows backing in its row 12 only
    for (int x = 10; x < 14; ++x) m(x, y) = 0;
  for (int y = 10; y < 14; ++y)  // hole B (x 20..23): no backing
    for (int x = 20; x < 24; ++x) m(x, y) = 0;
  struct Probe {
    int calls = 0;
    bool outside_holes = false;
  } probe;
  auto shows = [](const void* c, int y, int32_t begin, int32_t end) {
    auto& p = *static_cast<Probe*>(const_cast<void*>(c));
    ++p.calls;
    if (y < 10 || y >= 14 || !((begin == 10 && end == 14) || (begin == 20 && end == 24)))
      p.outside_holes = true;
    return y == 12 && begin == 10;
  };
  RunMask out;
  CleanupScratch scratch;
  const CleanupStats stats =
      clean_mask(RunMask::from_mask(m.view()), {4, 50}, out, scratch, shows, &probe);
  EXPECT_EQ(stats.holes_filled, 1);
  EXPECT_EQ(stats.gaps_kept, 1);
  EXPECT_FALSE(probe.outside_holes);
  EXPECT_LE(probe.calls, 8);  // 4 rows of each hole at most, fewer once A is known
  const Mask r = out.to_mask();
  EXPECT_EQ(r(11, 11), 0);    // A open
  EXPECT_EQ(r(21, 11), 255);  // B filled
  // Without the test both are filled.
  EXPECT_EQ(clean_mask(RunMask::from_mask(m.view()), {4, 50}, out, scratch).holes_filled, 2);
}

TEST(Cleanup, DisabledIsIdentity) {
  Mask m(9, 4, 0);
  m(1, 1) = 255;
  m(4, 2) = 255;
  const RunMask in = RunMask::from_mask(m.view());
  RunMask out;
  CleanupScratch scratch;
  clean_mask(in, {0, 0}, out, scratch);
  EXPECT_EQ(out, in);
}

}  // namespace
}  // namespace studio::keyer

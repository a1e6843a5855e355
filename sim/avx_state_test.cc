// The renderer's entry points run their legacy-SSE arithmetic with the AVX upper state clean
// (sim/src/clean_upper.h): a caller that leaves the YMM upper halves dirty (the in-process
// keyer's AVX2 kernel did, issue 20) must not make every render 1.8x dearer. Checked with the
// processor's own record of the state in use (XGETBV with ECX = 1, XINUSE: bit 2 = the upper
// halves of YMM0-15, bit 6 = the upper halves of ZMM0-15), not with a timing.
#include <gtest/gtest.h>

#include <cstdint>

#if defined(__x86_64__)
#include <cpuid.h>
#endif

#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::sim {
namespace {

#if defined(__x86_64__)
constexpr uint64_t kUpperState = (1u << 2) | (1u << 6);

bool xinuse_readable() {
  unsigned a, b, c, d;
  if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & bit_OSXSAVE) || !(c & bit_AVX)) return false;
  if (!__get_cpuid_count(0xD, 1, &a, &b, &c, &d)) return false;
  return (a & (1u << 2)) != 0;  // XGETBV with ECX = 1
}

__attribute__((noinline)) uint64_t xinuse() {
  uint32_t lo, hi;
  asm volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(1));
  return (uint64_t(hi) << 32) | lo;
}

// Leaves the YMM upper halves dirty, as a 256-bit AVX routine returning without vzeroupper does.
__attribute__((noinline)) void dirty_upper() {
  asm volatile("vpcmpeqd %%ymm15, %%ymm15, %%ymm15" ::: "xmm15");
}
#endif

TEST(SimAvxState, RenderClearsDirtyUpperState) {
#if defined(__x86_64__)
  if (!xinuse_readable()) {
    // No AVX or no XINUSE: no dirty upper state can exist, or none can be observed; the render
    // must still work.
    const auto s = SimulatedStudio::create(ring_cameras({.count = 1, .overhead = false}));
    ASSERT_TRUE(s.has_value());
    Image<Rgb8> image;
    s->render(0, 10, &image, nullptr);
    EXPECT_EQ(image.width(), 704);
    return;
  }
  StudioOptions o;
  o.threads = 1;
  const auto studio = SimulatedStudio::create(ring_cameras({.count = 2, .overhead = false}), o);
  ASSERT_TRUE(studio.has_value()) << studio.error().message;
  Image<Rgb8> image;
  Mask mask;
  studio->render(0, 5, &image, &mask);  // warm: first-call allocations, tables

  dirty_upper();
  const uint64_t before = xinuse();
  EXPECT_NE(before & kUpperState, 0u) << "control: the state was not dirty (XINUSE " << before << ")";
  dirty_upper();
  studio->render(0, 6, &image, &mask);
  const uint64_t after_render = xinuse();
  EXPECT_EQ(after_render & kUpperState, 0u) << "render() ran with dirty upper state";

  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  dirty_upper();
  studio->render_all(7, &images, &masks);
  const uint64_t after_all = xinuse();
  EXPECT_EQ(after_all & kUpperState, 0u) << "render_all() ran with dirty upper state";
#else
  GTEST_SKIP() << "x86-64 only";
#endif
}

}  // namespace
}  // namespace studio::sim

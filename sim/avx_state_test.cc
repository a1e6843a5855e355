// The renderer's entry points run their legacy-SSE arithmetic with the AVX upper state clean
// (sim/src/clean_upper.h): a caller that leaves the YMM upper halves dirty (the in-process
// keyer's AVX2 kernel did, issue 20) must not make every render 1.8x dearer. Checked with the
// processor's own record of the state in use (XGETBV with ECX = 1, XINUSE: bit 2 = the upper
// halves of YMM0-15, bit 6 = the upper halves of ZMM0-15), not with a timing.
#include <gtest/gtest.h>

#include <cstdint>

#include "sim/cameras.h"
#include "sim/studio.h"
#include "support/avx_state.h"

namespace studio::sim {
namespace {

#if defined(__x86_64__)
using studio::testing::dirty_avx_upper;
using studio::testing::kAvxUpperState;
using studio::testing::xinuse;
using studio::testing::xinuse_readable;
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

  dirty_avx_upper();
  const uint64_t before = xinuse();
  EXPECT_NE(before & kAvxUpperState, 0u) << "control: the state was not dirty (XINUSE " << before << ")";
  dirty_avx_upper();
  studio->render(0, 6, &image, &mask);
  const uint64_t after_render = xinuse();
  EXPECT_EQ(after_render & kAvxUpperState, 0u) << "render() ran with dirty upper state";

  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  dirty_avx_upper();
  studio->render_all(7, &images, &masks);
  const uint64_t after_all = xinuse();
  EXPECT_EQ(after_all & kAvxUpperState, 0u) << "render_all() ran with dirty upper state";
#else
  GTEST_SKIP() << "x86-64 only";
#endif
}

}  // namespace
}  // namespace studio::sim

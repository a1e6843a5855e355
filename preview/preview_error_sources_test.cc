// Where the preview's error against a held-out camera comes from (issue 16; the analysis aid
// behind BENCHMARKS.md's preview quality rows; testing/held_out.h): the same 10 frames scored
//   - with the simulator's realism knobs switched off one at a time (for the feeding cameras and
//     the held-out one alike): what sensor noise, the cameras' ring lights, blue spill and
//     anti-aliased edges each cost the texturing;
//   - per region of the union of silhouettes (interior, rim, one silhouette only) and the
//     drawn pixels no selected camera saw (painted magenta here to count them);
//   - per camera: nearest-camera texturing from each studio camera in turn;
//   - with the visual hull: the share of the hull's excess, and the PSNR that excess alone
//     allows.
// PREVIEW_DUMP_DIR=<dir> writes, per frame and variant, the truth, the rendering and their
// difference (x4) side by side, 3x, for the first case of each test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "testing/held_out.h"

namespace studio::preview::held_out {
namespace {

class PreviewErrorSourcesTest : public HeldOutTest {
 protected:
  static Scoring scoring(bool dump) {
    Scoring s;
    s.texturer.unseen = {1, 0, 1};
    if (const char* d = std::getenv("PREVIEW_DUMP_DIR"); d && dump) s.dump_dir = d;
    return s;
  }
};

const std::vector<Variant> kModes{{"nearest", TextureMode::nearest}, {"blend", TextureMode::blend}};

sim::StudioOptions all_off() {
  sim::StudioOptions o;
  o.noise_sigma = 0;
  o.ring_light = 0;
  o.spill = 0;
  o.antialias = false;
  return o;
}

// The realism knobs one at a time, true surface, unseen points magenta. Measured (blend, dB):
// default 27.5, no noise 27.7, no ring light 27.6, no spill 28.2, no anti-aliasing 28.2, all
// off 28.6: spill and the anti-aliased edges (both at the rim, where the held-out camera mixes
// its own backing into the actor) are the largest effects; what remains with all off is the rim
// and the interior's creases and occlusion edges (bilinear resampling of 1-px detail) and the
// few points none of the three cameras sees. Nearest (16.5-16.9 dB) is not a texturing fault:
// 13 % of the held-out view's actor is hidden from the one camera 20 degrees away.
TEST_F(PreviewErrorSourcesTest, PerSimulatorEffectWithTheTrueSurface) {
  struct Case {
    const char* name;
    sim::StudioOptions o;
  };
  std::vector<Case> cases(6);
  cases[0].name = "default";
  cases[1].name = "no noise";
  cases[1].o.noise_sigma = 0;
  cases[2].name = "no ring light";
  cases[2].o.ring_light = 0;
  cases[3].name = "no spill";
  cases[3].o.spill = 0;
  cases[4].name = "no anti-aliasing";
  cases[4].o.antialias = false;
  cases[5] = {"all off", all_off()};
  for (const Case& c : cases) {
    Scoring s = scoring(&c == &cases[0]);
    s.sim = c.o;
    const auto r = evaluate(s, kModes, kFrames);
    for (std::size_t v = 0; v < kModes.size(); ++v)
      std::printf("%-17s %-8s %s\n", c.name, kModes[v].name.c_str(), r[v].line().c_str());
    const Breakdown &nearest = r[0], &blend = r[1];
    EXPECT_GT(blend.psnr(), nearest.psnr() + 5) << c.name;
    // The true surface: no excess; actor left undrawn (every camera keys the point as backing)
    // is rare.
    EXPECT_EQ(blend.rendered_only.px, 0u) << c.name;
    EXPECT_LT(blend.true_only.px, 50u) << c.name;
    EXPECT_GE(blend.interior.psnr(), 29.0) << c.name;
    // One camera cannot see what the held-out camera sees of the actor's sides: 13 % of the
    // drawn pixels; three cameras leave 0.3 %.
    EXPECT_GT(nearest.unseen, 10 * blend.unseen) << c.name;
  }
}

// Nearest-camera texturing from each studio camera in turn (true surface, knobs off). The
// held-out camera is 20 degrees from cam0 and 25 from cam1; the others 65 degrees and more: what
// they cannot see of the held-out view (magenta, counted) dominates their error.
TEST_F(PreviewErrorSourcesTest, PerCameraWithTheTrueSurface) {
  std::vector<Variant> each;
  for (int c = 0; c < 9; ++c) each.push_back({"cam" + std::to_string(c), TextureMode::nearest, c});
  Scoring s = scoring(true);
  s.sim = all_off();
  const auto r = evaluate(s, each, kFrames);
  for (std::size_t v = 0; v < each.size(); ++v)
    std::printf("%-5s %s\n", each[v].name.c_str(), r[v].line().c_str());
  for (std::size_t v = 2; v < each.size(); ++v) {
    EXPECT_GT(std::min(r[0].psnr(), r[1].psnr()), r[v].psnr()) << each[v].name;
    EXPECT_LT(std::max(r[0].unseen, r[1].unseen), r[v].unseen) << each[v].name;
  }
}

// The visual hull of the true masks: its excess (drawn where the held-out camera sees the
// backing) is half of the blend's error, and alone it bounds the PSNR below the 28 dB.
TEST_F(PreviewErrorSourcesTest, TheVisualHullsExcessBoundsTheBlend) {
  Scoring s = scoring(true);
  s.hull = true;
  const auto r = evaluate(s, kModes, kFrames);
  for (std::size_t v = 0; v < kModes.size(); ++v)
    std::printf("hull %-8s %s\n", kModes[v].name.c_str(), r[v].line().c_str());
  const Breakdown& blend = r[1];
  const Region all = blend.total();
  // The PSNR over the union were the excess the only error.
  const double bound =
      10 * std::log10(255.0 * 255.0 * 3 * double(all.px) / blend.rendered_only.squared);
  std::printf("the excess alone (%llu px of %llu) allows %.1f dB\n",
              (unsigned long long)blend.rendered_only.px, (unsigned long long)all.px, bound);
  EXPECT_GT(blend.psnr(), r[0].psnr() + 3);
  EXPECT_GT(blend.share(blend.rendered_only), 0.3);
  EXPECT_LT(bound, 28.0);
}

// What would lift the blend with the visual hull (issue 16's 28 dB): the hull's excess over a
// round body between ring cameras 2 pi / n apart is r (1 / cos(pi / n) - 1) (8 % of the radius
// with 8, 2 % with 16), whatever the grid; a finer grid only follows that hull more closely.
// Measured (2026-11-25, blend; excess = rendered-only px; the PSNR the excess alone allows):
//   8 ring, grid 96 (the node's)    20.5 dB, excess 2899 px (23.6 dB); undrawn actor 162 px
//   8 ring, grid 160                20.9 dB, excess 3269 px (23.2 dB); undrawn 47 px
//   16 ring, grid 96                23.5 dB, excess 1121 px (32.2 dB); undrawn 335 px (58 %)
//   16 ring, grid 160, push-out 10 mm  25.6 dB, excess 1844 px; undrawn 83 px
// Twice the cameras shrink the excess 2.6x; the undrawn actor then limits: at grid 96 the
// hull's flat facets cut inside the body by more than the 5 mm push-out and the carving cannot
// restore what is not there; a finer grid and a larger push-out recover it (the push-out adds
// excess back where the keys cannot carve it). With 8 cameras a larger push-out only adds
// excess (15 mm: 19.8 dB). 24 ring, grid 160, 10 mm: 26.0 dB. None reaches 28 dB.
TEST_F(PreviewErrorSourcesTest, MoreCamerasNotAFinerGridShrinkTheHullsExcess) {
  struct Case {
    const char* name;
    int cameras, cells;
    float inflate_m;
  };
  const std::vector<Case> cases{{"8 ring, grid 96", 9, 96, 0.005f},
                                {"8 ring, grid 160", 9, 160, 0.005f},
                                {"16 ring, grid 96", 17, 96, 0.005f},
                                {"16 ring, g160, 10mm", 17, 160, 0.010f}};
  std::vector<Breakdown> blends;
  for (const Case& c : cases) {
    Scoring s = scoring(false);
    s.hull = true;
    s.cameras = c.cameras;
    s.hull_cells = c.cells;
    s.texturer.inflate_m = c.inflate_m;
    const auto r = evaluate(s, kModes, kFrames);
    const Breakdown& blend = r[1];
    const double bound =
        10 * std::log10(255.0 * 255.0 * 3 * double(blend.total().px) / blend.rendered_only.squared);
    std::printf("%-19s nearest %5.1f dB, blend %s; excess %llu px allows %.1f dB\n", c.name,
                r[0].psnr(), blend.line().c_str(), (unsigned long long)blend.rendered_only.px,
                bound);
    blends.push_back(blend);
  }
  // The grid alone moves the blend by less than 1 dB; twice the cameras shrink the excess by
  // more than half and gain more than 2 dB; then the finer grid with a larger push-out gains
  // again (the undrawn actor recovered).
  EXPECT_LT(std::abs(blends[1].psnr() - blends[0].psnr()), 1.0);
  EXPECT_LT(2 * blends[2].rendered_only.px, blends[0].rendered_only.px);
  EXPECT_GT(blends[2].psnr(), blends[0].psnr() + 2.0);
  EXPECT_LT(blends[3].true_only.px, blends[2].true_only.px / 2);
  EXPECT_GT(blends[3].psnr(), blends[2].psnr() + 1.0);
}

}  // namespace
}  // namespace studio::preview::held_out

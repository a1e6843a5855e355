// Accuracy of the keyer on the simulated studio (sim/): 6 cameras at 704x576, every
// realism knob on (sensor noise, cloth fall-off and seams, blue spill, the cameras' blue ring
// light on the actor, soft floor shadows, a projected picture on the back wall, area-integrated
// edges and, in the scene, motion blur over a 1/50 s shutter).
//
// Two truths, both from the simulator (sim/studio.h):
// - the true matte, cut at 1/2: a pixel is actor when the actor covers at least half of the
//   image's own sub-samples of it (16, spread over the pixel's area and the shutter). This is the
//   mask the image shows, and what the keyer is scored against (the "true mask" for a
//   keyer: no keyer can see more than the exposure recorded);
// - the geometric silhouette: the ray through the pixel CENTRE at the frame's instant hits the
//   actor. This is what the visual hull is scored against. Without motion blur it differs from
//   the true matte only by sub-pixel ties; with motion blur a part that moves further than its
//   own width during the exposure is a faint smear that covers no pixel for half the shutter, so
//   even the exact matte reaches only IoU ~0.989 against it (KeyerSim.GeometricSilhouetteLimit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/mask_codec.h"
#include "keyer/keyer.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "test_frames.h"

namespace studio::keyer {
namespace {

sim::StudioOptions all_knobs_on(bool motion_blur, uint64_t actor_seed = 1) {
  sim::StudioOptions o;
  o.actor.seed = actor_seed;    // clothes, body, path
  o.motion_blur = motion_blur;  // antialias is on either way (space-time samples with blur)
  o.projected_image = true;
  return o;
}

bool empty(const Mask& m) {
  return std::all_of(m.pixels().begin(), m.pixels().end(), [](uint8_t p) { return p == 0; });
}

// The true matte cut at 1/2 (16 sub-samples: 8 of 16 is 128).
Mask matte_cut(const Image<uint8_t>& matte) {
  Mask m = matte;
  for (uint8_t& v : m.pixels()) v = v >= 128 ? 255 : 0;
  return m;
}

// Truth pixels whose 5x5 neighbourhood is entirely actor (away from the silhouette edge).
bool deep_inside(const Mask& m, int x, int y) {
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= m.width() || v >= m.height() || !m(u, v)) return false;
    }
  return true;
}

// The frames every test here scores: 8 poses (frames 0, 25, ..., 175) x 6 cameras, skipping
// cameras that do not see the actor.
constexpr int64_t kFrameStep = 25, kFrameEnd = 200;

struct Score {
  int masks = 0;
  double iou_sum = 0, geometric_iou_sum = 0, boundary_sum = 0, bytes_sum = 0, worst_iou = 1;
  long false_pos = 0, false_neg = 0;
  long dark_pixels = 0, dark_lost = 0, interior_lost = 0;
  double mean_iou() const { return iou_sum / masks; }  // against the true matte
  double mean_geometric_iou() const { return geometric_iou_sum / masks; }
  double mean_boundary() const { return boundary_sum / masks; }
};

Score score_keyer(bool motion_blur, uint64_t actor_seed = 1, int64_t frame_step = kFrameStep,
                  const KeyerOptions& options = {}) {
  Score s;
  auto studio =
      sim::SimulatedStudio::create(sim::ring_cameras(), all_knobs_on(motion_blur, actor_seed));
  EXPECT_TRUE(studio) << studio.error().message;
  auto keyer = Keyer::create(options);
  EXPECT_TRUE(keyer);
  if (!studio || !keyer) return s;
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> silhouettes;
  std::vector<Image<uint8_t>> mattes;
  RunMask mask;
  for (int64_t frame = 0; frame < kFrameEnd; frame += frame_step) {
    studio->render_all(frame, &images, &silhouettes, &mattes);
    for (int c = 0; c < studio->camera_count(); ++c) {
      if (empty(silhouettes[c])) continue;  // actor out of view
      EXPECT_TRUE(keyer->key(images[c].view(), mask));
      const Mask got = mask.to_mask();
      const Mask truth = matte_cut(mattes[c]);
      const double i = testing::iou(got, truth);
      s.iou_sum += i;
      s.worst_iou = std::min(s.worst_iou, i);
      s.geometric_iou_sum += testing::iou(got, silhouettes[c]);
      s.boundary_sum += testing::boundary_error(got, truth);
      s.bytes_sum += double(encode_mask(mask).size());
      ++s.masks;
      for (int y = 0; y < got.height(); ++y)
        for (int x = 0; x < got.width(); ++x) {
          const bool g = got(x, y) != 0, t = truth(x, y) != 0;
          s.false_pos += g && !t;
          s.false_neg += t && !g;
          // No false holes inside the actor, in particular where the clothes are dark.
          if (!deep_inside(silhouettes[c], x, y)) continue;
          const Rgb8 p = images[c](x, y);
          const bool dark = std::max({p.r, p.g, p.b}) < 60;
          s.dark_pixels += dark;
          if (!g) {
            ++s.interior_lost;
            s.dark_lost += dark;
          }
        }
    }
  }
  std::printf(
      "sim keyer (%s, actor %d): %d masks, mean IoU %.4f (worst %.4f; against the geometric "
      "silhouette %.4f), mean boundary error %.3f px, false pos %ld / neg %ld px, mean encoded "
      "mask %.0f bytes; interior pixels lost %ld (dark: %ld of %ld)\n",
      motion_blur ? "motion blur" : "anti-aliased", int(actor_seed), s.masks, s.mean_iou(),
      s.worst_iou, s.mean_geometric_iou(), s.mean_boundary(), s.false_pos, s.false_neg,
      s.bytes_sum / s.masks, s.interior_lost, s.dark_lost, s.dark_pixels);
  return s;
}

void expect_accurate(const Score& s) {
  ASSERT_GT(s.masks, 40);
  EXPECT_GE(s.mean_iou(), 0.99);       // the bound
  EXPECT_GE(s.worst_iou, 0.96);
  EXPECT_LE(s.mean_boundary(), 1.0);   // the bound
  EXPECT_LE(s.mean_boundary(), 0.15);  // what is reached (0.04-0.10 px): guards regressions
  EXPECT_EQ(s.dark_lost, 0);           // no false holes where the clothes are dark
  EXPECT_LE(s.interior_lost, 10);
  EXPECT_LE(s.bytes_sum / s.masks, 1500);
}

// The scene: every knob on, motion blur included. Measured: mean IoU 0.9923 (against
// the geometric silhouette 0.9860, whose limit here is 0.9892).
TEST(KeyerSim, AccurateOnSimulatedStudioWithAllRealismKnobs) {
  const Score s = score_keyer(true);
  expect_accurate(s);
  EXPECT_GE(s.mean_geometric_iou(), 0.98);
}

// The same poses without motion blur (a short shutter). Measured: mean IoU 0.9966; against the
// geometric silhouette 0.9943.
TEST(KeyerSim, AccurateWithAntiAliasedEdges) {
  const Score s = score_keyer(false);
  expect_accurate(s);
  EXPECT_GE(s.mean_geometric_iou(), 0.99);
}

// Edge refinement is what moves the cut to half coverage: without it the key's fixed clip levels
// cut edge pixels at ~60 % coverage on the lit cloth (measured on 24 masks, anti-aliased: mean IoU
// 0.9873 without, 0.9968 with).
TEST(KeyerSim, EdgeRefinementMovesTheCutToHalfCoverage) {
  KeyerOptions plain;
  plain.edge_refine = false;
  const Score without = score_keyer(false, 1, 50, plain);
  const Score with = score_keyer(false, 1, 50);
  EXPECT_GT(with.mean_iou(), without.mean_iou() + 0.005);
  EXPECT_LT(with.mean_boundary(), without.mean_boundary());
}

// Other actors (clothes from the simulator's palettes: dark trousers and shoes, black hair, grey,
// green or red shirts; other bodies and paths), 4 poses each: no false holes where the clothes
// are dark, and the same accuracy.
TEST(KeyerSim, NoFalseHolesAcrossActors) {
  long dark_pixels = 0;
  for (uint64_t seed = 2; seed <= 7; ++seed) {
    const Score s = score_keyer(true, seed, 50);
    ASSERT_GT(s.masks, 15) << "actor " << seed;
    EXPECT_GE(s.mean_iou(), 0.99) << "actor " << seed;  // measured 0.9921-0.9947
    EXPECT_LE(s.mean_boundary(), 1.0) << "actor " << seed;
    EXPECT_EQ(s.dark_lost, 0) << "actor " << seed;
    EXPECT_LE(s.interior_lost, 10) << "actor " << seed;
    dark_pixels += s.dark_pixels;
  }
  EXPECT_GT(dark_pixels, 1000);  // the palettes do put dark clothes deep inside the silhouettes
}

// How close the exact true matte, cut at 1/2, comes to the geometric silhouette: the bound on any
// keyer scored against the silhouette. With motion blur it stays below 0.99 (fast hands and feet
// smear; measured 0.9892), without it is a sub-pixel tie-break (measured 0.9956). The keyer
// comes within 0.005 of it in both.
TEST(KeyerSim, GeometricSilhouetteLimit) {
  for (bool blur : {true, false}) {
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), all_knobs_on(blur));
    ASSERT_TRUE(studio);
    std::vector<Mask> silhouettes;
    std::vector<Image<uint8_t>> mattes;
    double sum = 0;
    int n = 0;
    for (int64_t frame = 0; frame < kFrameEnd; frame += kFrameStep) {
      studio->render_all(frame, nullptr, &silhouettes, &mattes);
      for (int c = 0; c < studio->camera_count(); ++c) {
        if (empty(silhouettes[c])) continue;
        sum += testing::iou(matte_cut(mattes[c]), silhouettes[c]);
        ++n;
      }
    }
    const double limit = sum / n;
    std::printf("exact matte against the geometric silhouette (%s): IoU %.4f (%d masks)\n",
                blur ? "motion blur" : "anti-aliased", limit, n);
    if (blur) {
      EXPECT_LT(limit, 0.99);
    } else {
      EXPECT_GT(limit, 0.995);
    }
    const Score s = score_keyer(blur);
    EXPECT_GE(s.mean_geometric_iou(), limit - 0.005) << (blur ? "motion blur" : "anti-aliased");
  }
}

// Analysis aid (not run by default): per mask, false positives / negatives near the true
// outline (within 2 px) and away from it, for the default keyer, against the geometric
// silhouette. Environment: NOBLUR=1 scores the
// anti-aliased rendering, NOSHADOW=1 turns the floor shadow off.
TEST(KeyerSim, DISABLED_ErrorsPerCamera) {
  const bool blur = std::getenv("NOBLUR") == nullptr;
  auto options = all_knobs_on(blur);
  if (std::getenv("NOSHADOW")) options.shadow = 0;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), options);
  ASSERT_TRUE(studio);
  auto keyer = Keyer::create({});
  ASSERT_TRUE(keyer);
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> truths;
  RunMask mask;
  for (int64_t frame = 0; frame < kFrameEnd; frame += kFrameStep) {
    studio->render_all(frame, &images, &truths);
    for (int c = 0; c < studio->camera_count(); ++c) {
      const Mask& truth = truths[c];
      if (empty(truth)) continue;
      ASSERT_TRUE(keyer->key(images[c].view(), mask));
      const Mask got = mask.to_mask();
      long fp_near = 0, fp_far = 0, fn_near = 0, fn_far = 0, area = 0;
      for (int y = 0; y < got.height(); ++y)
        for (int x = 0; x < got.width(); ++x) {
          area += truth(x, y) != 0;
          if (bool(got(x, y)) == bool(truth(x, y))) continue;
          bool near = false;
          for (int dy = -2; dy <= 2 && !near; ++dy)
            for (int dx = -2; dx <= 2 && !near; ++dx) {
              const int u = x + dx, v = y + dy;
              near = u >= 0 && v >= 0 && u < got.width() && v < got.height() &&
                     bool(truth(u, v)) != bool(truth(x, y));
            }
          if (got(x, y))
            (near ? fp_near : fp_far)++;
          else
            (near ? fn_near : fn_far)++;
          if (!near && std::getenv("DUMP")) {
            const Rgb8 p = images[c](x, y), q = studio->background(c)(x, y);
            std::printf("  far %s at (%d, %d): image %d %d %d, empty studio %d %d %d\n",
                        got(x, y) ? "FP" : "FN", x, y, p.r, p.g, p.b, q.r, q.g, q.b);
          }
        }
      std::printf(
          "frame %3d cam%d area %6ld IoU %.4f  FP near %4ld far %3ld  FN near %4ld far %3ld\n",
          int(frame), c, area, testing::iou(got, truth), fp_near, fp_far, fn_near, fn_far);
    }
  }
}

}  // namespace
}  // namespace studio::keyer

// Accuracy of the keyer on the simulated studio (capture/sim): 6 cameras at 704x576, every
// realism knob on (sensor noise, cloth fall-off and seams, blue spill, the cameras' blue ring
// light on the actor, soft floor shadows, a projected picture on the back wall, and either motion
// blur or anti-aliased edges: the simulator renders one or the other), scored against the exact
// true masks (pixel CENTRE hit by the actor at the frame's instant).
//
// What bounds the score. The simulator mixes each edge pixel from 4 sub-samples: 4 instants of
// the shutter (motion blur) or a 2x2 grid at +-0.25 px (anti-aliasing). A pixel with 2 of 4
// sub-samples on the actor is then ambiguous: its centre (or centre instant) lies between the
// samples, on either side. Even the exact sub-sample coverage, cut per pixel, does not beat
// IoU ~0.986 against the centre truth (KeyerSim.NearThePerPixelInformationLimit computes it from
// finer renders); the keyer's per-pixel cut is checked to be within 0.001 of that limit. Getting
// past it needs sub-pixel reasoning across neighbours (a symmetric 3x3 filter of the EXACT
// coverage reaches 0.991) and an alpha that matches coverage, which blue spill (a mix of the
// backing into the actor's grazing edge, indistinguishable per pixel from partial coverage) and
// non-grey clothes prevent; see BENCHMARKS.md ("Keyer and mask codec") for the measurements.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "capture/sim/cameras.h"
#include "capture/sim/studio.h"
#include "core/mask_codec.h"
#include "keyer/keyer.h"
#include "test_frames.h"

namespace studio::keyer {
namespace {

sim::StudioOptions all_knobs_on(bool motion_blur, uint64_t actor_seed = 1) {
  sim::StudioOptions o;
  o.actor.seed = actor_seed;    // clothes, body, path
  o.motion_blur = motion_blur;  // the simulator anti-aliases edges when blur is off
  o.projected_image = true;
  return o;
}

bool empty(const Mask& m) {
  return std::all_of(m.pixels().begin(), m.pixels().end(), [](uint8_t p) { return p == 0; });
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
  double iou_sum = 0, boundary_sum = 0, bytes_sum = 0, worst_iou = 1;
  long false_pos = 0, false_neg = 0;
  long dark_pixels = 0, dark_lost = 0, interior_lost = 0;
  double mean_iou() const { return iou_sum / masks; }
  double mean_boundary() const { return boundary_sum / masks; }
};

Score score_keyer(bool motion_blur, uint64_t actor_seed = 1, int64_t frame_step = kFrameStep) {
  Score s;
  auto studio =
      sim::SimulatedStudio::create(sim::ring_cameras(), all_knobs_on(motion_blur, actor_seed));
  EXPECT_TRUE(studio) << studio.error().message;
  auto keyer = Keyer::create({});
  EXPECT_TRUE(keyer);
  if (!studio || !keyer) return s;
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> truths;
  RunMask mask;
  for (int64_t frame = 0; frame < kFrameEnd; frame += frame_step) {
    studio->render_all(frame, &images, &truths);
    for (int c = 0; c < studio->camera_count(); ++c) {
      if (empty(truths[c])) continue;  // actor out of view
      EXPECT_TRUE(keyer->key(images[c].view(), mask));
      const Mask got = mask.to_mask();
      const double i = testing::iou(got, truths[c]);
      s.iou_sum += i;
      s.worst_iou = std::min(s.worst_iou, i);
      s.boundary_sum += testing::boundary_error(got, truths[c]);
      s.bytes_sum += double(encode_mask(mask).size());
      ++s.masks;
      for (int y = 0; y < got.height(); ++y)
        for (int x = 0; x < got.width(); ++x) {
          const bool g = got(x, y) != 0, t = truths[c](x, y) != 0;
          s.false_pos += g && !t;
          s.false_neg += t && !g;
          // No false holes inside the actor, in particular where the clothes are dark.
          if (!deep_inside(truths[c], x, y)) continue;
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
      "sim keyer (%s, actor %d): %d masks, mean IoU %.4f (worst %.4f), mean boundary error %.3f "
      "px, "
      "false pos %ld / neg %ld px, mean encoded mask %.0f bytes; interior pixels lost %ld "
      "(dark: %ld of %ld)\n",
      motion_blur ? "motion blur" : "anti-aliased", int(actor_seed), s.masks, s.mean_iou(),
      s.worst_iou, s.mean_boundary(), s.false_pos, s.false_neg, s.bytes_sum / s.masks,
      s.interior_lost, s.dark_lost, s.dark_pixels);
  return s;
}

void expect_accurate(const Score& s, double min_mean_iou) {
  ASSERT_GT(s.masks, 40);
  EXPECT_GE(s.mean_iou(), min_mean_iou);
  EXPECT_GE(s.worst_iou, 0.96);
  EXPECT_LE(s.mean_boundary(), 1.0);   // the bound
  EXPECT_LE(s.mean_boundary(), 0.25);  // what is reached (0.17-0.19 px): guards regressions
  EXPECT_EQ(s.dark_lost, 0);           // no false holes where the clothes are dark
  EXPECT_LE(s.interior_lost, 10);
  EXPECT_LE(s.bytes_sum / s.masks, 1500);
}

// The scene: every knob on, motion blur included. Measured: mean IoU 0.9858 (0.9847
// before clean-up kept holes that show the clean backing open).
TEST(KeyerSim, AccurateOnSimulatedStudioWithAllRealismKnobs) {
  expect_accurate(score_keyer(true), 0.985);
}

// The same poses rendered with anti-aliased (2x2 supersampled) edges instead of motion blur.
// Measured: mean IoU 0.9839 (0.9829 before).
TEST(KeyerSim, AccurateWithAntiAliasedEdges) { expect_accurate(score_keyer(false), 0.983); }

// Other actors (clothes from the simulator's palettes: dark trousers and shoes, black hair, grey,
// green or red shirts; other bodies and paths), 4 poses each: no false holes where the clothes
// are dark, and the same accuracy.
TEST(KeyerSim, NoFalseHolesAcrossActors) {
  long dark_pixels = 0;
  for (uint64_t seed = 2; seed <= 7; ++seed) {
    const Score s = score_keyer(true, seed, 50);
    ASSERT_GT(s.masks, 15) << "actor " << seed;
    EXPECT_GE(s.mean_iou(), 0.985) << "actor " << seed;  // measured 0.9868-0.9881
    EXPECT_LE(s.mean_boundary(), 1.0) << "actor " << seed;
    EXPECT_EQ(s.dark_lost, 0) << "actor " << seed;
    EXPECT_LE(s.interior_lost, 10) << "actor " << seed;
    dark_pixels += s.dark_pixels;
  }
  EXPECT_GT(dark_pixels, 1000);  // the palettes do put dark clothes deep inside the silhouettes
}

// The best any per-pixel binary cut can do on these frames: the true masks of the simulator's
// own sub-samples (rendered exactly: the shutter instants at 16x the frame rate, the 2x2 grid as
// a 2x camera whose pixel centres are the sub-sample positions), counted per pixel and cut at
// 2 of 4. The keyer must come within 0.001 of it (measured 0.0001 / 0.0006 below). Also prints what
// a symmetric 3x3 filter of the exact counts would reach (sub-pixel localisation; not achievable
// without exact coverage).
struct Limit {
  double per_pixel = 0, filtered = 0;
};

Limit coverage_limit(bool motion_blur) {
  const std::vector<Camera> cams = sim::ring_cameras();
  auto opts = all_knobs_on(motion_blur);
  auto studio = sim::SimulatedStudio::create(cams, opts);
  std::vector<Camera> fine_cams = cams;
  auto fine_opts = opts;
  const int64_t fps_factor = 16;  // shutter 0.5 of 1/25 s, 4 samples: offsets +-1, +-3 at 400 fps
  if (motion_blur) {
    EXPECT_EQ(opts.blur_samples, 4);
    EXPECT_DOUBLE_EQ(opts.shutter, 0.5);
    fine_opts.fps = opts.fps * double(fps_factor);
    fine_opts.motion_blur = false;
  } else {
    for (Camera& c : fine_cams) {  // pixel U of the 2x camera = sub-sample U/2 - 0.25
      c.width *= 2;
      c.height *= 2;
      c.intrinsics.fx *= 2;
      c.intrinsics.fy *= 2;
      c.intrinsics.cx = 2 * c.intrinsics.cx + 0.5;
      c.intrinsics.cy = 2 * c.intrinsics.cy + 0.5;
    }
  }
  auto fine = sim::SimulatedStudio::create(fine_cams, fine_opts);
  EXPECT_TRUE(studio && fine);
  Limit limit;
  if (!studio || !fine) return limit;
  std::vector<Mask> truths, sub[4];
  int n = 0;
  for (int64_t frame = 0; frame < kFrameEnd; frame += kFrameStep) {
    studio->render_all(frame, nullptr, &truths);
    if (motion_blur) {
      const int64_t offsets[4] = {-3, -1, 1, 3};
      for (int k = 0; k < 4; ++k)
        fine->render_all(fps_factor * frame + offsets[k], nullptr, &sub[k]);
    } else {
      fine->render_all(frame, nullptr, &sub[0]);
    }
    for (int c = 0; c < studio->camera_count(); ++c) {
      const Mask& truth = truths[c];
      if (empty(truth)) continue;
      const int w = truth.width(), h = truth.height();
      Image<int> count(w, h, 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          int k = 0;
          if (motion_blur) {
            for (const auto& s : sub) k += s[c](x, y) != 0;
          } else {
            const Mask& f = sub[0][c];
            k = (f(2 * x, 2 * y) != 0) + (f(2 * x + 1, 2 * y) != 0) + (f(2 * x, 2 * y + 1) != 0) +
                (f(2 * x + 1, 2 * y + 1) != 0);
          }
          count(x, y) = k;
        }
      Mask cut(w, h, 0), filtered(w, h, 0);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          cut(x, y) = count(x, y) >= 2 ? 255 : 0;
          if (x == 0 || y == 0 || x + 1 == w || y + 1 == h) continue;
          int sum = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) sum += count(x + dx, y + dy);
          filtered(x, y) = sum > 18 || (sum == 18 && count(x, y) >= 2) ? 255 : 0;
        }
      limit.per_pixel += testing::iou(cut, truth);
      limit.filtered += testing::iou(filtered, truth);
      ++n;
    }
  }
  limit.per_pixel /= n;
  limit.filtered /= n;
  std::printf(
      "coverage limit (%s): per-pixel cut at 2/4 IoU %.4f, 3x3-filtered exact coverage "
      "%.4f (%d masks)\n",
      motion_blur ? "motion blur" : "anti-aliased", limit.per_pixel, limit.filtered, n);
  return limit;
}

TEST(KeyerSim, NearThePerPixelInformationLimit) {
  for (bool blur : {true, false}) {
    const Limit limit = coverage_limit(blur);
    const Score s = score_keyer(blur);
    ASSERT_GT(s.masks, 40);
    EXPECT_GE(s.mean_iou(), limit.per_pixel - 0.001) << (blur ? "motion blur" : "anti-aliased");
    EXPECT_LT(limit.per_pixel, 0.99);  // why the 0.99 is out of reach for a per-pixel cut
  }
}

// Analysis aid (not run by default): per mask, false positives / negatives near the true
// outline (within 2 px) and away from it, for the default keyer. Environment: NOBLUR=1 scores the
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

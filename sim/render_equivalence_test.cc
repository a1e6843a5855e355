// The default renderer against the pre-issue-20 renderer kept as the reference
// (StudioOptions::reference_renderer): same images, true masks and true mattes bit for bit, with
// every realism knob, on ring cameras, distorted and skewed cameras, motion blur and the frame
// code; and the sensor noise's statistics (mean, variance, independence between neighbours,
// frames and cameras).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::sim {
namespace {

SimulatedStudio make(StudioOptions o, std::vector<Camera> cams, bool reference) {
  o.reference_renderer = reference;
  auto s = SimulatedStudio::create(std::move(cams), o);
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  return std::move(*s);
}

// Renders `frames` on every camera with both renderers and counts differing bytes; also renders
// the default one into a reused image and mask (the row-wise path) and without a mask.
void expect_identical(const StudioOptions& o, const std::vector<Camera>& cams,
                      const std::vector<int64_t>& frames, bool with_matte = true) {
  const SimulatedStudio fast = make(o, cams, false), ref = make(o, cams, true);
  Image<Rgb8> reused;
  Mask reused_mask;
  long compared = 0;
  for (int64_t f : frames) {
    for (int c = 0; c < fast.camera_count(); ++c) {
      Image<Rgb8> a, b;
      Mask ma, mb;
      Image<uint8_t> ta, tb;
      fast.render(c, f, &a, &ma, with_matte ? &ta : nullptr);
      ref.render(c, f, &b, &mb, with_matte ? &tb : nullptr);
      ASSERT_EQ(a.pixels(), b.pixels()) << "image, camera " << c << " frame " << f;
      ASSERT_EQ(ma.pixels(), mb.pixels()) << "mask, camera " << c << " frame " << f;
      if (with_matte)
        ASSERT_EQ(ta.pixels(), tb.pixels()) << "matte, camera " << c << " frame " << f;
      fast.render(c, f, &reused, &reused_mask);  // previous frame's pixels in the buffers
      ASSERT_EQ(reused.pixels(), b.pixels()) << "reused image, camera " << c << " frame " << f;
      ASSERT_EQ(reused_mask.pixels(), mb.pixels());
      Image<Rgb8> no_mask;
      fast.render(c, f, &no_mask, nullptr);
      ASSERT_EQ(no_mask.pixels(), b.pixels()) << "no mask, camera " << c << " frame " << f;
      // A control that the comparison can fail: the actor is on the image.
      long actor = 0;
      for (uint8_t m : mb.pixels()) actor += m != 0;
      EXPECT_GT(actor, 500) << "camera " << c << " frame " << f;
      ++compared;
    }
  }
  EXPECT_EQ(compared, long(frames.size()) * fast.camera_count());
}

TEST(RenderEquivalence, DefaultKnobsRingCamerasBitIdentical) {
  expect_identical({}, ring_cameras(), {0, 13, 77, 140, 260, 333});
}

TEST(RenderEquivalence, NoiseOffBitIdentical) {
  StudioOptions o;
  o.noise_sigma = 0;
  expect_identical(o, ring_cameras(), {5, 121, 250});
}

TEST(RenderEquivalence, DistortedAndSkewedCamerasBitIdentical) {
  std::vector<Camera> cams = ring_cameras({.count = 3});
  cams[0].distortion = Distortion::radial(-0.12, 0.03);
  cams[1].distortion = Distortion::opencv(0.05, -0.02, 0.001, -0.0005, 0.0);
  cams[2].intrinsics.skew = 2.0;
  cams[2].intrinsics.fy = cams[2].intrinsics.fx * 1.03;
  expect_identical({}, cams, {25, 260});
}

TEST(RenderEquivalence, CloseWideCameraBitIdentical) {
  // A short focal length close to the actor: wide pixel cones, large parts on the image.
  std::vector<Camera> cams = ring_cameras({.count = 2, .overhead = false});
  for (Camera& c : cams) c.intrinsics.fx = c.intrinsics.fy = 180;
  expect_identical({}, cams, {40, 90});
}

TEST(RenderEquivalence, MotionBlurFrameCodeAndProjectedImageBitIdentical) {
  StudioOptions o;
  o.motion_blur = true;
  o.blur_samples = 8;
  o.frame_code = true;
  o.projected_image = true;
  expect_identical(o, ring_cameras({.count = 3}), {30, 200});
}

TEST(RenderEquivalence, AntialiasOffAndAaSamples4BitIdentical) {
  StudioOptions o;
  o.antialias = false;
  expect_identical(o, ring_cameras({.count = 2}), {60});
  o.antialias = true;
  o.aa_samples = 4;
  o.shadow = 0;
  expect_identical(o, ring_cameras({.count = 2}), {60});
}

// The edge pixels' shading once per part (the default) against every sub-sample shaded
// (aa_shade_every_sample): the same true masks and mattes (coverage is exact either way), and
// only edge pixels differ, by about a grey level (measured at the default knobs: mean 0.9-1.6,
// at most 15, at ~1 000 pixels a camera). Control: some pixels do differ (the option is live).
TEST(RenderEquivalence, EdgeShadingOncePerPartStaysWithinAGreyLevel) {
  StudioOptions every;
  every.aa_shade_every_sample = true;
  auto a = SimulatedStudio::create(ring_cameras(), {});
  auto b = SimulatedStudio::create(ring_cameras(), every);
  ASSERT_TRUE(a && b);
  long changed = 0, edge = 0;
  double sum = 0;
  int worst = 0;
  for (int64_t f : {13, 140, 260}) {
    for (int c = 0; c < a->camera_count(); ++c) {
      Image<Rgb8> ia, ib;
      Mask ma, mb;
      Image<uint8_t> ta, tb;
      a->render(c, f, &ia, &ma, &ta);
      b->render(c, f, &ib, &mb, &tb);
      ASSERT_EQ(ma.pixels(), mb.pixels());
      ASSERT_EQ(ta.pixels(), tb.pixels());
      for (int y = 0; y < ia.height(); ++y)
        for (int x = 0; x < ia.width(); ++x) {
          const Rgb8 p = ia(x, y), q = ib(x, y);
          const int d = std::max({std::abs(p.r - q.r), std::abs(p.g - q.g), std::abs(p.b - q.b)});
          const bool on_edge = ta(x, y) != 0 && ta(x, y) != 255;
          edge += on_edge;
          if (d == 0) continue;
          // Differences only where the sub-samples do not all agree: partly covered pixels,
          // or fully covered ones beside the silhouette (sub-samples on two parts, or the
          // neighbour's edge test).
          ++changed;
          sum += (std::abs(p.r - q.r) + std::abs(p.g - q.g) + std::abs(p.b - q.b)) / 3.0;
          worst = std::max(worst, d);
        }
    }
  }
  ASSERT_GT(changed, 0) << "the option changed nothing";
  const double mean = sum / double(changed);
  std::printf("edge shading once per part vs every sub-sample: %ld px changed (%ld partly "
              "covered), mean %.2f, max %d grey levels\n",
              changed, edge, mean, worst);
  EXPECT_LT(mean, 2.0);
  EXPECT_LE(worst, 24);
  EXPECT_LT(changed, 3 * edge);
}

// Noise = image - background on background pixels away from the actor and its shadow (the
// top quarter of a ring camera's image: walls, above the actor's head in these views).
struct NoiseField {
  std::vector<double> d;  // green channel differences, row-major over the sampled pixels
  int w = 0, h = 0;
};

NoiseField noise_of(const SimulatedStudio& s, int camera, int64_t frame) {
  Image<Rgb8> img;
  Mask mask;
  s.render(camera, frame, &img, &mask);
  NoiseField n;
  n.w = img.width();
  n.h = img.height() / 4;
  for (int y = 0; y < n.h; ++y) {
    for (int x = 0; x < n.w; ++x) {
      EXPECT_EQ(mask(x, y), 0);
      n.d.push_back(double(img(x, y).g) - s.background(camera)(x, y).g);
    }
  }
  return n;
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  const double n = double(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    sa += a[i];
    sb += b[i];
    saa += a[i] * a[i];
    sbb += b[i] * b[i];
    sab += a[i] * b[i];
  }
  const double cov = sab / n - sa / n * sb / n;
  return cov / std::sqrt((saa / n - sa / n * sa / n) * (sbb / n - sb / n * sb / n));
}

TEST(RenderEquivalence, NoiseHasTheDistributionAndIsIndependent) {
  StudioOptions o;
  o.noise_sigma = 2.5;
  const SimulatedStudio s = make(o, ring_cameras({.count = 2, .overhead = false}), false);
  const NoiseField a = noise_of(s, 0, 10), b = noise_of(s, 0, 11), c = noise_of(s, 1, 10);
  // ~100 000 samples: the mean's standard error is 2.5 / 318 = 0.008, a correlation's 0.003.
  double sum = 0, sum2 = 0;
  for (double v : a.d) {
    sum += v;
    sum2 += v * v;
  }
  const double n = double(a.d.size()), mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.04);
  EXPECT_NEAR(sigma, 2.5, 0.08);  // rounding to integers adds 1/12 to the variance: 2.52
  EXPECT_LT(std::abs(correlation(a.d, b.d)), 0.015) << "frame to frame";
  EXPECT_LT(std::abs(correlation(a.d, c.d)), 0.015) << "camera to camera";
  // Neighbours across and down, and the next frame's pixel one to the right (a shifted copy of
  // one frame's noise in the next would show here).
  std::vector<double> l, r, u, dn, nb;
  for (int y = 0; y + 1 < a.h; ++y) {
    for (int x = 0; x + 1 < a.w; ++x) {
      const std::size_t i = std::size_t(y) * a.w + x;
      l.push_back(a.d[i]);
      r.push_back(a.d[i + 1]);
      u.push_back(a.d[i]);
      dn.push_back(a.d[i + a.w]);
      nb.push_back(b.d[i + 1]);
    }
  }
  EXPECT_LT(std::abs(correlation(l, r)), 0.015) << "across";
  EXPECT_LT(std::abs(correlation(u, dn)), 0.015) << "down";
  EXPECT_LT(std::abs(correlation(l, nb)), 0.015) << "next frame, shifted";
  // Positive control: the same frame twice is the same noise.
  EXPECT_GT(correlation(a.d, noise_of(s, 0, 10).d), 0.999);
}

}  // namespace
}  // namespace studio::sim

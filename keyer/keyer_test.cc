#include "keyer/keyer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "../src/key_kernels.h"
#include "core/mask_codec.h"
#include "keyer/reference_keyer.h"
#include "support/avx_state.h"
#include "support/masks.h"
#include "test_frames.h"

namespace studio::keyer {
namespace {

using testing::make_frame;

Image<Bgr8> to_bgr(const Image<Rgb8>& in) {
  Image<Bgr8> out(in.width(), in.height());
  for (std::size_t i = 0; i < in.pixels().size(); ++i) {
    const Rgb8 p = in.pixels()[i];
    out.pixels()[i] = Bgr8{p.b, p.g, p.r};
  }
  return out;
}

Image<Rgb8> random_image(std::mt19937& rng, int w, int h) {
  Image<Rgb8> im(w, h);
  for (auto& p : im.pixels()) p = Rgb8{uint8_t(rng()), uint8_t(rng()), uint8_t(rng())};
  return im;
}

TEST(KeyKernels, SimdMatchesScalarOnEveryWidth) {
  std::mt19937 rng(1);
  const auto& best = detail::best_kernels();
  const auto& scalar = detail::scalar_kernels();
  std::vector<uint64_t> a(8), b(8);
  for (int w = 0; w < 300; ++w) {
    std::vector<uint8_t> row(3 * w), plate(3 * w);
    for (auto& v : row) v = uint8_t(rng());
    for (auto& v : plate) v = uint8_t(rng());
    for (int k = 0; k < 3; ++k) {
      const auto p = detail::make_chroma_params(k, (k + 1) % 3, (k + 2) % 3, uint8_t(rng()));
      std::fill(a.begin(), a.end(), ~0ull);
      std::fill(b.begin(), b.end(), ~0ull);
      best.chroma(row.data(), w, p, a.data());
      scalar.chroma(row.data(), w, p, b.data());
      ASSERT_TRUE(std::equal(a.begin(), a.begin() + (w + 63) / 64, b.begin())) << "width " << w;
    }
    const uint8_t lo = uint8_t(rng());
    best.diff(row.data(), plate.data(), w, lo, a.data());
    scalar.diff(row.data(), plate.data(), w, lo, b.data());
    ASSERT_TRUE(std::equal(a.begin(), a.begin() + (w + 63) / 64, b.begin())) << "width " << w;
  }
}

// The row kernels return with the AVX upper state clean (the caller's legacy-SSE code would
// otherwise pay a merge penalty on every instruction: 1.8x the capture server's simulator, issue
// 20). GCC 12 drops the vzeroupper it owes before a tail call into non-AVX code; the kernels
// clear it themselves. Control: the state is seen dirty right after dirtying it.
TEST(KeyKernels, ReturnWithTheAvxUpperStateClean) {
#if defined(__x86_64__)
  if (!studio::testing::xinuse_readable()) GTEST_SKIP() << "no AVX / XGETBV(1) on this CPU";
  const auto& best = detail::best_kernels();
  std::vector<uint8_t> row(3 * 704, 40), plate(3 * 704, 30);
  std::vector<uint64_t> bits(11);
  const auto p = detail::make_chroma_params(2, 0, 1, 20);
  for (int w : {704, 700, 31}) {  // a tail after the 32-pixel blocks, and none but a tail
    studio::testing::dirty_avx_upper();
    ASSERT_NE(studio::testing::xinuse() & studio::testing::kAvxUpperState, 0u) << "control";
    studio::testing::clean_avx_upper();
    best.chroma(row.data(), w, p, bits.data());
    EXPECT_EQ(studio::testing::xinuse() & studio::testing::kAvxUpperState, 0u)
        << best.name << " chroma, width " << w;
    best.diff(row.data(), plate.data(), w, 10, bits.data());
    EXPECT_EQ(studio::testing::xinuse() & studio::testing::kAvxUpperState, 0u)
        << best.name << " diff, width " << w;
  }
#else
  GTEST_SKIP() << "x86-64 only";
#endif
}

TEST(KeyKernels, BitsToRunsMatchesPixels) {
  std::mt19937 rng(2);
  for (int w : {1, 63, 64, 65, 128, 200}) {
    std::vector<uint64_t> bits((w + 63) / 64, 0);
    Mask m(w, 1, 0);
    for (int x = 0; x < w; ++x)
      if (rng() % 3) {
        bits[x / 64] |= 1ull << (x % 64);
        m(x, 0) = 255;
      }
    RunMask r(w, 1);
    detail::bits_to_runs(bits.data(), w, 0, r);
    r.finish();
    EXPECT_EQ(r, RunMask::from_mask(m.view())) << w;
  }
}

// Without clean-up the fast keyer's mask is exactly the reference keyer's, for any options.
TEST(Keyer, EqualsReferenceKeyerWithoutCleanup) {
  std::mt19937 rng(4);
  for (KeyMode mode : {KeyMode::kBlue, KeyMode::kGreen, KeyMode::kDifference}) {
    for (int trial = 0; trial < 10; ++trial) {
      KeyerOptions o;
      o.mode = mode;
      o.cleanup = {0, 0};
      o.edge_refine = false;  // edge refinement is a stage after the per-pixel key
      o.gain = 0.5f + (rng() % 100) / 50.0f;
      o.clip_black = float(rng() % 60);
      o.clip_white = o.clip_black + 1 + float(rng() % 100);
      o.diff_low = float(rng() % 60);
      o.diff_high = o.diff_low + 1 + float(rng() % 100);
      o.matte_threshold = 0.05f + (rng() % 95) / 100.0f;
      auto keyer = Keyer::create(o);
      ASSERT_TRUE(keyer) << keyer.error().message;
      const int w = 1 + int(rng() % 90), h = 1 + int(rng() % 20);
      const Image<Rgb8> im = random_image(rng, w, h), plate = random_image(rng, w, h);
      if (mode == KeyMode::kDifference) {
        ASSERT_TRUE(keyer->capture_plate(plate.view()));
      }
      const Mask ref = reference_key(im.view(), o, &plate);
      RunMask got;
      ASSERT_TRUE(keyer->key(im.view(), got));
      ASSERT_EQ(got.to_mask().pixels(), ref.pixels()) << key_mode_name(mode) << " trial " << trial;
      const Image<Bgr8> bgr = to_bgr(im);
      ASSERT_TRUE(keyer->key(bgr.view(), got));
      ASSERT_EQ(got.to_mask().pixels(), ref.pixels()) << "bgr " << key_mode_name(mode);
    }
  }
}

TEST(Keyer, KeysSyntheticActorAccurately) {
  for (bool green : {false, true}) {
    const auto f = make_frame(352, 288, 0.3, green);
    KeyerOptions o;
    o.mode = green ? KeyMode::kGreen : KeyMode::kBlue;
    auto keyer = Keyer::create(o);
    ASSERT_TRUE(keyer);
    RunMask mask;
    ASSERT_TRUE(keyer->key(f.image.view(), mask));
    EXPECT_GT(support::iou(mask.to_mask(), f.truth), 0.98) << (green ? "green" : "blue");
  }
}

// Bayer sensor: mosaic the frame (BGGR), demosaic as the capture stage does (bilinear and
// edge-aware), key. Demosaicing blurs colour at edges, so the mask may shift by a fraction of a
// pixel (mean boundary error under 1 px).
TEST(Keyer, KeysBayerDemosaicedFrames) {
  const auto f = make_frame(704, 576, 1.1);
  cv::Mat raw(f.image.height(), f.image.width(), CV_8UC1);
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      const Rgb8 p = f.image(x, y);
      const bool ey = y % 2 == 0, ex = x % 2 == 0;
      raw.at<uint8_t>(y, x) = ey && ex ? p.b : (!ey && !ex ? p.r : p.g);
    }
  auto keyer = Keyer::create({});
  for (auto code : {cv::COLOR_BayerRG2RGB, cv::COLOR_BayerRG2RGB_EA}) {
    cv::Mat rgb;
    cv::demosaicing(raw, rgb, code);  // OpenCV names BGGR "RG" (from its second row)
    ImageView<const Rgb8> view(reinterpret_cast<const Rgb8*>(rgb.data), rgb.cols, rgb.rows, rgb.step);
    ASSERT_GT(view(5, 5).b, view(5, 5).r + 50);  // really RGB: the backing reads blue
    RunMask mask;
    ASSERT_TRUE(keyer->key(view, mask));
    const Mask got = mask.to_mask();
    EXPECT_GT(support::iou(got, f.truth), 0.97) << "demosaic " << code;
    EXPECT_LT(testing::boundary_error(got, f.truth), 1.0) << "demosaic " << code;
  }
}

TEST(Keyer, DifferenceKeyAgainstCleanPlate) {
  KeyerOptions o;
  o.mode = KeyMode::kDifference;
  auto keyer = Keyer::create(o);
  ASSERT_TRUE(keyer);
  RunMask mask;
  const auto f = make_frame(176, 144, 0.0, false, 3.0, 7);
  EXPECT_FALSE(keyer->key(f.image.view(), mask));  // no plate yet
  // Plate: the same backing without the actor (averaged over 4 noisy frames).
  for (unsigned i = 0; i < 4; ++i) {
    auto empty = make_frame(176, 144, 0.0, false, 3.0, 100 + i);
    for (int y = 0; y < 144; ++y)
      for (int x = 0; x < 176; ++x) {
        const double shade = 0.8 + 0.3 * double(x) / 176 - 0.1 * double(y) / 144;
        if (f.truth(x, y) || empty.truth(x, y))
          empty.image(x, y) = Rgb8{uint8_t(35 * shade), uint8_t(75 * shade), uint8_t(205 * shade)};
      }
    ASSERT_TRUE(keyer->capture_plate(empty.image.view()));
  }
  EXPECT_EQ(keyer->plate_frames(), 4);
  ASSERT_TRUE(keyer->key(f.image.view(), mask));
  EXPECT_GT(support::iou(mask.to_mask(), f.truth), 0.95);
  const auto other = make_frame(100, 80, 0.0);
  auto err = keyer->key(other.image.view(), mask);
  ASSERT_FALSE(err);
  EXPECT_NE(err.error().message.find("100x80"), std::string::npos);
  EXPECT_FALSE(keyer->capture_plate(other.image.view()));
  keyer->clear_plate();
  EXPECT_FALSE(keyer->has_plate());
}

// A small enclosed region of clean backing (a gap between arm and body) stays open; a small
// enclosed region keyed as backing but not clean (bluish dark cloth, backing between the clips)
// is a false hole and is filled. With keep_backing_gaps off both are filled.
TEST(Keyer, KeepsRealGapsFillsFalseHoles) {
  const Rgb8 backing{30, 66, 212}, cloth{20, 20, 24}, bluish{20, 30, 100};  // excess 146, 0, 70
  Image<Rgb8> im(80, 60, backing);
  for (int y = 10; y < 50; ++y)
    for (int x = 20; x < 60; ++x) im(x, y) = cloth;
  for (int y = 20; y < 26; ++y)
    for (int x = 25; x < 29; ++x) im(x, y) = backing;  // the gap
  for (int y = 20; y < 26; ++y)
    for (int x = 45; x < 49; ++x) im(x, y) = bluish;  // alpha 0.375 < 0.5: keyed as backing
  for (bool keep : {true, false}) {
    KeyerOptions o;
    o.cleanup.keep_backing_gaps = keep;
    auto keyer = Keyer::create(o);
    ASSERT_TRUE(keyer);
    RunMask mask;
    ASSERT_TRUE(keyer->key(im.view(), mask));
    EXPECT_EQ(mask.contains(26, 22), !keep) << keep;
    EXPECT_TRUE(mask.contains(46, 22)) << keep;
    EXPECT_EQ(mask.area(), keep ? 40u * 40 - 24 : 40u * 40) << keep;
    const Image<Bgr8> bgr = to_bgr(im);
    ASSERT_TRUE(keyer->key(bgr.view(), mask));
    EXPECT_EQ(mask.contains(26, 22), !keep) << "bgr " << keep;
  }
  // Difference key: the gap matches the plate (clean backing), the false hole differs by less
  // than the cut but more than diff_low.
  KeyerOptions o;
  o.mode = KeyMode::kDifference;
  auto keyer = Keyer::create(o);
  ASSERT_TRUE(keyer);
  Image<Rgb8> plate(80, 60, backing), frame = plate;
  for (int y = 10; y < 50; ++y)
    for (int x = 20; x < 60; ++x) frame(x, y) = cloth;
  for (int y = 20; y < 26; ++y)
    for (int x = 25; x < 29; ++x) frame(x, y) = backing;
  for (int y = 20; y < 26; ++y)
    for (int x = 45; x < 49; ++x) frame(x, y) = Rgb8{30, 66, 192};  // diff 20: alpha 1/3
  ASSERT_TRUE(keyer->capture_plate(plate.view()));
  RunMask mask;
  ASSERT_TRUE(keyer->key(frame.view(), mask));
  EXPECT_FALSE(mask.contains(26, 22));
  EXPECT_TRUE(mask.contains(46, 22));
}

TEST(Keyer, SoftAlphaFollowsTheFormula) {
  KeyerOptions o;
  o.clip_black = 20;
  o.clip_white = 60;
  auto keyer = Keyer::create(o);
  Image<Rgb8> im(4, 1);
  im(0, 0) = {50, 50, 50};    // no excess: actor
  im(1, 0) = {30, 30, 70};    // excess 40: half
  im(2, 0) = {30, 60, 200};   // backing
  im(3, 0) = {10, 10, 25};    // excess 15: actor
  Mask alpha(4, 1);
  ASSERT_TRUE(keyer->soft_alpha(im.view(), alpha.view()));
  EXPECT_EQ(alpha(0, 0), 255);
  EXPECT_NEAR(alpha(1, 0), 128, 1);
  EXPECT_EQ(alpha(2, 0), 0);
  EXPECT_EQ(alpha(3, 0), 255);
  Mask wrong(3, 1);
  EXPECT_FALSE(keyer->soft_alpha(im.view(), wrong.view()));
}

TEST(Keyer, SpillSuppressionLimitsKeyChannel) {
  Image<Rgb8> im(2, 1);
  im(0, 0) = {100, 90, 160};
  im(1, 0) = {100, 90, 80};
  suppress_spill(im.view(), KeyMode::kBlue, 1.0f);
  EXPECT_EQ(im(0, 0), (Rgb8{100, 90, 100}));
  EXPECT_EQ(im(1, 0), (Rgb8{100, 90, 80}));
  Image<Bgr8> g(1, 1);
  g(0, 0) = {40, 200, 60};
  suppress_spill(g.view(), KeyMode::kGreen, 0.5f);
  EXPECT_EQ(g(0, 0), (Bgr8{40, 130, 60}));
}

TEST(KeyerOptions, ValidateNamesTheBadField) {
  KeyerOptions o;
  EXPECT_TRUE(o.validate());
  o.clip_white = 10;
  auto r = o.validate();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message.rfind("clip_white", 0), 0u);
  o = {};
  o.matte_threshold = 0;
  EXPECT_FALSE(Keyer::create(o));
  o = {};
  o.cleanup.max_hole_area = -1;
  EXPECT_FALSE(o.validate());
  EXPECT_FALSE(parse_key_mode("red"));
  EXPECT_EQ(*parse_key_mode("green"), KeyMode::kGreen);
}

// The keyer's masks of a moving actor code to far fewer bytes than the paper's ~4000.
TEST(Keyer, KeyedActorMasksEncodeSmall) {
  auto keyer = Keyer::create({});
  RunMask mask;
  double bytes = 0;
  for (int i = 0; i < 3; ++i) {
    const auto f = make_frame(704, 576, 0.5 * i, false, 3.0, 10 + i);
    ASSERT_TRUE(keyer->key(f.image.view(), mask));
    const auto enc = encode_mask(mask);
    ASSERT_EQ(*decode_mask(enc), mask);
    bytes += enc.size();
  }
  EXPECT_LT(bytes / 3, 1500);
}

}  // namespace
}  // namespace studio::keyer

#include "core/mask_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace studio {
namespace {

constexpr MaskCoding kCodings[] = {MaskCoding::kRuns, MaskCoding::kRowDelta};

Mask random_mask(std::mt19937& rng, int w, int h) {
  Mask m(w, h, 0);
  std::bernoulli_distribution on((rng() % 101) / 100.0);
  for (auto& p : m.pixels()) p = on(rng) ? 255 : 0;
  return m;
}

// A blob shaped like an actor: body ellipse, head, two legs, an arm; boundaries move smoothly.
RunMask actor_mask(int w, int h, double phase) {
  Mask m(w, h, 0);
  auto ellipse = [&](double cx, double cy, double rx, double ry) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double dx = (x - cx) / rx, dy = (y - cy) / ry;
        if (dx * dx + dy * dy <= 1.0) m(x, y) = 255;
      }
  };
  ellipse(w * 0.5, h * 0.18, w * 0.04, h * 0.06);
  ellipse(w * 0.5, h * 0.42, w * 0.08, h * 0.2);
  ellipse(w * (0.46 + 0.02 * std::sin(phase)), h * 0.75, w * 0.03, h * 0.2);
  ellipse(w * (0.54 - 0.02 * std::sin(phase)), h * 0.75, w * 0.03, h * 0.2);
  ellipse(w * (0.62 + 0.03 * std::cos(phase)), h * 0.35, w * 0.1, h * 0.025);
  return RunMask::from_mask(m.view());
}

TEST(MaskCodec, RoundTripsRandomMasks) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    const int w = int(rng() % 130), h = int(rng() % 40);
    const RunMask mask = RunMask::from_mask(random_mask(rng, w, h).view());
    for (MaskCoding c : kCodings) {
      const auto bytes = encode_mask(mask, c);
      auto decoded = decode_mask(bytes);
      ASSERT_TRUE(decoded) << decoded.error().message;
      ASSERT_TRUE(decoded->valid());
      EXPECT_EQ(*decoded, mask) << "coding " << int(c) << " " << w << "x" << h;
    }
  }
}

TEST(MaskCodec, RoundTripsEdgeCases) {
  std::vector<RunMask> masks;
  masks.emplace_back(0, 0);
  masks.emplace_back(0, 5);
  masks.emplace_back(7, 0);
  Mask full(kMaxMaskSide, 2, 255);
  masks.push_back(RunMask::from_mask(full.view()));
  Mask stripes(33, 9, 0);
  for (int y = 0; y < 9; ++y)
    for (int x = y % 2; x < 33; x += 2) stripes(x, y) = 255;
  masks.push_back(RunMask::from_mask(stripes.view()));
  for (auto& m : masks) m.finish();
  for (const RunMask& m : masks)
    for (MaskCoding c : kCodings) {
      auto decoded = decode_mask(encode_mask(m, c));
      ASSERT_TRUE(decoded) << decoded.error().message;
      EXPECT_EQ(*decoded, m);
    }
}

TEST(MaskCodec, ActorMasksAreSmall) {
  double rle = 0, delta = 0;
  const int n = 8;
  for (int i = 0; i < n; ++i) {
    const RunMask m = actor_mask(704, 576, i * 0.7);
    const auto a = encode_mask(m, MaskCoding::kRuns), b = encode_mask(m, MaskCoding::kRowDelta);
    EXPECT_EQ(*decode_mask(b), m);
    rle += a.size();
    delta += b.size();
  }
  // The row-delta coding beats plain runs by far on smooth silhouettes.
  EXPECT_LT(delta / n, 600.0);
  EXPECT_LT(delta, rle / 3);
}

TEST(MaskCodec, DecodeReusesStorage) {
  const RunMask a = actor_mask(100, 80, 0.1), b = actor_mask(100, 80, 1.3);
  auto ra = decode_mask(encode_mask(a));
  ASSERT_TRUE(ra);
  EXPECT_EQ(*ra, a);
  const studio::Run* storage = ra->runs().data();
  auto rb = decode_mask(encode_mask(b), std::move(*ra));
  ASSERT_TRUE(rb);
  EXPECT_EQ(*rb, b);
  if (b.runs().size() <= a.runs().size()) {
    EXPECT_EQ(rb->runs().data(), storage);
  }
  EXPECT_FALSE(decode_mask(std::vector<uint8_t>{1, 2, 3}, std::move(*rb)));
  // A default-constructed mask (no row index) may be passed too.
  auto rc = decode_mask(encode_mask(a), RunMask());
  ASSERT_TRUE(rc);
  EXPECT_EQ(*rc, a);
}

TEST(MaskCodec, RejectsMalformedHeaders) {
  using B = std::vector<uint8_t>;
  EXPECT_FALSE(decode_mask(B{}));
  EXPECT_FALSE(decode_mask(B{kMaskMagic}));
  EXPECT_FALSE(decode_mask(B{0x00, 2, 1, 1, 0}));           // bad magic
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 9, 1, 1, 0}));     // unknown coding
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 0x80}));        // truncated varint
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 0x81, 0x80, 0x04, 1}));  // width 65537
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01, 1}));
  const auto err = decode_mask(B{0x00, 2, 1, 1, 0});
  EXPECT_EQ(err.error().message.find('\n'), std::string::npos);
  auto empty = decode_mask(encode_mask(RunMask(704, 576)));
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->width(), 704);
  EXPECT_EQ(empty->height(), 576);
  EXPECT_TRUE(empty->valid());
}

TEST(MaskCodec, RejectsBadRunsAndTrailingData) {
  using B = std::vector<uint8_t>;
  // kRuns, 4x1: one run gap 0 len 5 -> leaves the row.
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 4, 1, 1, 0, 4}));
  // 3 runs in a 4-wide row cannot be disjoint and non-touching.
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 4, 1, 3, 0, 0, 0, 0, 0, 0}));
  // Valid 4x1 with run [1,3), then a trailing byte.
  EXPECT_TRUE(decode_mask(B{kMaskMagic, 1, 4, 1, 1, 1, 1}));
  EXPECT_FALSE(decode_mask(B{kMaskMagic, 1, 4, 1, 1, 1, 1, 0}));
  // kRowDelta: row 0 explicit (bit 1) with garbage; row delta moving a begin past its end.
  RunMask two(10, 2);
  two.push_run(0, 2, 5);
  two.push_run(1, 2, 5);
  two.finish();
  auto bytes = encode_mask(two, MaskCoding::kRowDelta);
  EXPECT_TRUE(decode_mask(bytes));
  bytes.push_back(0);
  EXPECT_FALSE(decode_mask(bytes));
}

// Every prefix of a valid encoding is an error; every single-bit flip is an error or a valid mask.
TEST(MaskCodec, TruncationAndBitFlipsNeverMisbehave) {
  std::mt19937 rng(5);
  for (MaskCoding c : kCodings) {
    const RunMask m = actor_mask(120, 90, 0.4);
    const auto bytes = encode_mask(m, c);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      auto r = decode_mask(std::span(bytes.data(), n));
      EXPECT_FALSE(r) << "prefix " << n << " of " << bytes.size() << " decoded";
    }
    for (std::size_t i = 0; i < bytes.size(); ++i)
      for (int b = 0; b < 8; ++b) {
        auto flipped = bytes;
        flipped[i] ^= uint8_t(1u << b);
        auto r = decode_mask(flipped);
        if (r) {
          EXPECT_TRUE(r->valid());
          // A valid decode re-encodes to exactly the same bytes (the encoding is canonical).
          EXPECT_EQ(encode_mask(*r, c), flipped) << "byte " << i << " bit " << b;
        }
      }
  }
}

TEST(MaskCodec, RandomBytesNeverMisbehave) {
  std::mt19937 rng(99);
  int accepted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<uint8_t> bytes(rng() % 64);
    for (auto& b : bytes) b = uint8_t(rng());
    if (bytes.size() >= 2 && trial % 2) {
      bytes[0] = kMaskMagic;
      bytes[1] = uint8_t(1 + trial % 4 / 2);
    }
    auto r = decode_mask(bytes);
    if (r) {
      ++accepted;
      EXPECT_TRUE(r->valid());
    }
  }
  EXPECT_LT(accepted, 20000);
}

TEST(MaskCodec, EncoderRejectsOversizeMasks) {
  EXPECT_THROW(encode_mask(RunMask(kMaxMaskSide + 1, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace studio

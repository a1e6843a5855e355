// The simulated camera: studio frame numbers and genlock capture times, real-time pacing,
// deterministic pictures shared across instances, simulated features with read-back.
#include "capture/sim_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <thread>

#include "core/clock.h"
#include "sim/cameras.h"

namespace studio::capture {
namespace {

using namespace std::chrono_literals;

SimSourceOptions small_options(bool paced) {
  sim::RingOptions ring;
  ring.width = 176;
  ring.height = 144;
  ring.focal_px = 140;
  SimSourceOptions o;
  o.camera = sim::ring_cameras(ring)[1];
  o.paced = paced;
  o.clock.period_ns = 20'000'000;  // 50 fps keeps the test short
  return o;
}

double mean_level(const Image<Rgb8>& img) {
  double s = 0;
  for (const auto& p : img.pixels()) s += p.r + p.g + p.b;
  return s / (3.0 * img.pixels().size());
}

TEST(SimFrameSource, PacedFramesFollowTheStudioClock) {
  auto src = SimFrameSource::create(small_options(true));
  ASSERT_TRUE(src) << src.error().message;
  ASSERT_TRUE((*src)->start());
  const auto& clock = small_options(true).clock;
  std::optional<uint64_t> prev, first;
  for (int i = 0; i < 10; ++i) {
    auto f = (*src)->next(1s);
    ASSERT_TRUE(f && *f) << "no frame";
    const Frame& fr = **f;
    EXPECT_EQ(clock.frame_at(fr.capture_ns), fr.frame);
    EXPECT_EQ(fr.capture_ns, clock.time_of(fr.frame) + clock.period_ns / 2);
    timespec ts{};
    clock_gettime(CLOCK_REALTIME, &ts);
    EXPECT_GE(int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec, fr.capture_ns);  // never early
    if (prev) {
      EXPECT_GT(fr.frame, *prev);
    }
    if (!first) first = fr.frame;
    prev = fr.frame;
    EXPECT_EQ(fr.image.width(), 176);
  }
  const auto st = (*src)->stats();
  EXPECT_EQ(st.frames, 10u);
  // Frames are consecutive unless the (loaded) machine made us skip; skips are counted.
  EXPECT_EQ(*prev - *first, 9 + st.drops);
  (*src)->stop();
  auto after = (*src)->next(1s);
  ASSERT_TRUE(after);
  EXPECT_FALSE(*after);  // stopped: returns promptly with nothing
}

// Like a streaming camera's buffer pool: a consumer held up for fewer frame periods than the
// source has buffers gets every frame, in order (a host stall costs latency, not frames); held
// up longer, the frames beyond the pool are lost and counted. Control: the same stall with 2
// buffers loses frames. Paced, in real time at 50 fps.
TEST(SimFrameSource, ALateConsumerGetsEveryFrameTheBuffersHold) {
  auto run = [](int buffers, std::chrono::milliseconds stall) {
    SimSourceOptions o = small_options(true);
    o.buffer_frames = buffers;
    auto src = SimFrameSource::create(o);
    EXPECT_TRUE(src) << src.error().message;
    EXPECT_TRUE((*src)->start());
    auto first = (*src)->next(1s);
    EXPECT_TRUE(first && *first);
    std::this_thread::sleep_for(stall);
    uint64_t last = (**first).frame;
    for (int i = 0; i < 12; ++i) {  // catch up (each frame due already, then paced again)
      auto f = (*src)->next(1s);
      EXPECT_TRUE(f && *f);
      last = (**f).frame;
    }
    const auto st = (*src)->stats();
    (*src)->stop();
    EXPECT_EQ(last - (**first).frame, 12 + st.drops);  // every frame delivered or counted
    return st.drops;
  };
  EXPECT_GE(SimSourceOptions{}.buffer_frames, 16);  // the default rides out 15 periods
  // 5 periods (100 ms at 50 fps) behind: 8 buffers hold them (one period of slack for a loaded
  // machine's late wake-up).
  EXPECT_EQ(run(8, 100ms), 0u);
  EXPECT_GE(run(2, 100ms), 2u);  // control: a pool of 2 overflows
}

TEST(SimFrameSource, PacedPictureRenderedAheadIsTheFramesOwn) {
  // Paced, the next frame is rendered in the half period before its instant: what arrives (at
  // or after the instant) is exactly that frame's picture, also after waits that ran out before
  // and after the render ahead (short timeouts, tried until a frame comes).
  auto src = SimFrameSource::create(small_options(true));
  ASSERT_TRUE(src) << src.error().message;
  ASSERT_TRUE((*src)->start());
  for (int i = 0; i < 4; ++i) {
    Expected<std::optional<Frame>> f = std::optional<Frame>();
    for (int attempt = 0; attempt < 400 && f && !*f; ++attempt) f = (*src)->next(3ms);
    ASSERT_TRUE(f && *f) << "no frame";
    Image<Rgb8> expected;
    (*src)->studio().render(0, int64_t((*f)->frame), &expected, nullptr);
    EXPECT_EQ((*f)->image.pixels(), expected.pixels()) << "frame " << (*f)->frame;
    EXPECT_NE(mean_level(expected), 0.0);
  }
}

TEST(SimFrameSource, FrameArrivesAfterTheCamerasReadout) {
  // readout_ns models exposure end + read-out + transfer: no frame reaches the consumer before
  // capture_ns + readout_ns; an ideal camera (0) delivers from the instant on (control: the
  // same source without readout delivers before capture_ns + readout at least once).
  auto arrival_after_capture = [](int64_t readout_ns) {
    SimSourceOptions o = small_options(true);
    o.readout_ns = readout_ns;
    auto src = SimFrameSource::create(o);
    EXPECT_TRUE(src) << src.error().message;
    EXPECT_TRUE((*src)->start());
    int64_t least = INT64_MAX;
    for (int i = 0; i < 6; ++i) {
      auto f = (*src)->next(1s);
      EXPECT_TRUE(f && *f) << "no frame";
      if (!f || !*f) break;
      least = std::min(least, realtime_ns() - (*f)->capture_ns);
    }
    return least;
  };
  constexpr int64_t kReadout = 8'000'000;
  EXPECT_GE(arrival_after_capture(kReadout), kReadout);
  EXPECT_LT(arrival_after_capture(0), kReadout);
  SimSourceOptions bad = small_options(true);
  bad.readout_ns = 2 * bad.clock.period_ns;
  auto refused = SimFrameSource::create(bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("readout"), std::string::npos);
}

TEST(SimFrameSource, SameFrameSamePictureAcrossInstances) {
  auto a = SimFrameSource::create(small_options(false));
  auto b = SimFrameSource::create(small_options(false));
  ASSERT_TRUE(a && b);
  ASSERT_TRUE((*a)->start() && (*b)->start());
  auto fa = (*a)->next(1s).value().value();
  auto fb = (*b)->next(1s).value().value();
  auto fa2 = (*a)->next(1s).value().value();
  EXPECT_EQ(fa2.frame, fa.frame + 1);
  if (fb.frame == fa.frame) {
    EXPECT_EQ(fa.image.pixels(), fb.image.pixels());
  } else if (fb.frame == fa2.frame) {
    EXPECT_EQ(fa2.image.pixels(), fb.image.pixels());
  }
}

TEST(SimFrameSource, FeaturesClampReadBackAndChangeThePicture) {
  auto src = SimFrameSource::create(small_options(false));
  ASSERT_TRUE(src);
  ASSERT_TRUE((*src)->start());
  const double base = mean_level((*src)->next(1s).value()->image);
  EXPECT_EQ((*src)->set_feature("Gain", 6.0).value(), 6.0);
  const double gained = mean_level((*src)->next(1s).value()->image);
  EXPECT_GT(gained, base * 1.5);                             // +6 dB doubles unsaturated levels
  EXPECT_EQ((*src)->set_feature("Gain", 99).value(), 24.0);  // clamped, read back
  EXPECT_EQ((*src)->set_feature("Gain", 0).value(), 0.0);
  EXPECT_EQ((*src)->set_feature("ExposureTime", 5000).value(), 5000.0);
  const double darker = mean_level((*src)->next(1s).value()->image);
  EXPECT_LT(darker, base * 0.6);
  EXPECT_EQ((*src)->set_feature("ExposureTime", 1e9).value(), 20000.0);  // frame period
  EXPECT_EQ((*src)->set_feature("Focus", -3).value(), 0.0);
  EXPECT_FALSE((*src)->set_feature("Zoom", 1));
  EXPECT_FALSE((*src)->set_feature("Gain", NAN));
  bool found = false;
  for (const auto& f : (*src)->features())
    if (f.name == "Focus") {
      found = true;
      EXPECT_EQ(f.value, 0.0);
      EXPECT_EQ(f.max, 1.0);
    }
  EXPECT_TRUE(found);
  // Defocus blurs: neighbouring pixels differ less.
  auto sharp_src = SimFrameSource::create(small_options(false)).value();
  ASSERT_TRUE(sharp_src->start());
  ASSERT_TRUE(sharp_src->set_feature("ExposureTime", 20000));
  ASSERT_TRUE(sharp_src->set_feature("ExposureTime", 10000));
  auto sharp = sharp_src->next(1s).value()->image;
  ASSERT_TRUE(sharp_src->set_feature("Focus", 1.0));
  auto blurred = sharp_src->next(1s).value()->image;
  auto gradient = [](const Image<Rgb8>& im) {
    double g = 0;
    for (int y = 0; y < im.height(); ++y)
      for (int x = 1; x < im.width(); ++x) g += std::abs(int(im(x, y).b) - int(im(x - 1, y).b));
    return g;
  };
  EXPECT_LT(gradient(blurred), gradient(sharp) * 0.7);
}

// The same frame from two sources, started here (paced: their frames are the studio clock's): the
// images of the first frame both delivered; empty images when none matched within 8 frames.
std::pair<Image<Rgb8>, Image<Rgb8>> same_frame(SimFrameSource& first, SimFrameSource& second) {
  if (!first.start() || !second.start()) return {};
  std::map<uint64_t, Image<Rgb8>> seen;
  for (int i = 0; i < 4; ++i)
    if (auto f = first.next(1s); f && *f) seen.emplace((*f)->frame, (*f)->image);
  for (int i = 0; i < 8; ++i)
    if (auto f = second.next(1s); f && *f && seen.count((*f)->frame))
      return {seen.at((*f)->frame), (*f)->image};
  return {};
}

TEST(SimFrameSource, WithGammaTheControlsActBeforeTheTransferCurve) {
  // A camera publishing Gamma 0.5: Gain +6.02 dB (x2) and red x1.44 scale its delivered values by
  // 2^0.5 and (2 x 1.44)^0.5; the same controls on a camera without Gamma by 2 and 2.88.
  SimSourceOptions o = small_options(false);
  o.gamma = 0.5;
  auto plain = SimFrameSource::create(small_options(false)).value();
  auto curved = SimFrameSource::create(o).value();
  EXPECT_NEAR(curved->set_feature("Gain", 20 * std::log10(2.0)).value(), 6.0206, 1e-3);
  EXPECT_EQ(curved->set_feature("BalanceRatioRed", 1.44).value(), 1.44);
  EXPECT_FALSE(curved->set_feature("Gamma", 1.0)) << "read-only";
  bool listed = false;
  for (const auto& f : curved->features())
    if (f.name == "Gamma") listed = f.value == 0.5 && !f.writable;
  EXPECT_TRUE(listed);
  for (const auto& f : plain->features()) EXPECT_NE(f.name, "Gamma");
  const auto [a, b] = same_frame(*plain, *curved);
  ASSERT_FALSE(a.pixels().empty()) << "no common frame";
  double ga = 0, gb = 0, ra = 0, rb = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Rgb8 p = a.pixels()[i], q = b.pixels()[i];
    if (p.g < 170) ga += p.g, gb += q.g;  // unsaturated after x1.41
    if (p.r < 140) ra += p.r, rb += q.r;  // after x1.70
  }
  EXPECT_NEAR(gb / ga, std::sqrt(2.0), 0.01);
  EXPECT_NEAR(rb / ra, std::sqrt(2.0 * 1.44), 0.015);
  o.gamma = 0.05;
  EXPECT_FALSE(SimFrameSource::create(o)) << "gamma out of range";
}

TEST(SimFrameSource, BalanceRatiosScaleRedAndBlueAgainstGreen) {
  // The same frame from a camera with ratios 1 and one white-balanced red x1.25, blue x0.8.
  auto plain = SimFrameSource::create(small_options(false)).value();
  auto balanced = SimFrameSource::create(small_options(false)).value();
  EXPECT_EQ(balanced->set_feature("BalanceRatioRed", 1.25).value(), 1.25);
  EXPECT_EQ(balanced->set_feature("BalanceRatioBlue", 0.8).value(), 0.8);
  EXPECT_EQ(balanced->set_feature("BalanceRatioBlue", 9).value(), 4.0);  // clamped, read back
  EXPECT_EQ(balanced->set_feature("BalanceRatioBlue", 0.8).value(), 0.8);
  const auto [a, b] = same_frame(*plain, *balanced);
  ASSERT_FALSE(a.pixels().empty()) << "no common frame";
  double ra = 0, rb = 0, ba = 0, bb = 0;
  std::size_t green_differs = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Rgb8 p = a.pixels()[i], q = b.pixels()[i];
    green_differs += p.g != q.g;
    if (p.r < 190) ra += p.r, rb += q.r;  // unsaturated after x1.25
    ba += p.b, bb += q.b;
  }
  EXPECT_EQ(green_differs, 0u);
  EXPECT_NEAR(rb / ra, 1.25, 0.01);
  EXPECT_NEAR(bb / ba, 0.8, 0.01);
  bool listed = false;
  for (const auto& f : balanced->features())
    if (f.name == "BalanceRatioRed") listed = f.value == 1.25 && f.min == 0.25 && f.max == 4;
  EXPECT_TRUE(listed);
  EXPECT_FALSE(balanced->set_feature("BalanceRatioRed", NAN));
}

TEST(SimFrameSource, RejectsBadOptions) {
  auto o = small_options(true);
  o.gain_db = 30;
  auto r = SimFrameSource::create(o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("Gain"), std::string::npos);
  o = small_options(true);
  o.camera.id.clear();
  EXPECT_FALSE(SimFrameSource::create(o));
}

}  // namespace
}  // namespace studio::capture

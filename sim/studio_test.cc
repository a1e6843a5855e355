// The simulated studio renderer: exact true masks, determinism, keyable background, realism knobs.
#include <gtest/gtest.h>

#include <random>

#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::sim {
namespace {

SimulatedStudio make(StudioOptions o = {}, std::vector<Camera> cams = ring_cameras()) {
  auto s = SimulatedStudio::create(std::move(cams), o);
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  return std::move(*s);
}

// Pixels whose 5x5 neighbourhood in the mask is uniform (away from the silhouette edge).
bool interior(const Mask& m, int x, int y, uint8_t value) {
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= m.width() || v >= m.height()) return false;
      if (m(u, v) != value) return false;
    }
  }
  return true;
}

// Mask pixel <=> ray through the pixel centre hits the true solid: checked on every pixel near
// the silhouette and on random pixels elsewhere, with the independent world-frame code path.
void expect_exact_mask(const SimulatedStudio& studio, int64_t frame) {
  const FrameTruth truth = studio.truth(frame);
  std::mt19937_64 rng(frame);
  for (int c = 0; c < studio.camera_count(); ++c) {
    const Camera& cam = studio.cameras()[c];
    Mask mask;
    studio.render(c, frame, nullptr, &mask);
    const Eigen::Vector3d centre = cam.centre_in_world();
    auto check = [&](int u, int v) {
      const bool hit = truth.body.ray_hit(centre, cam.pixel_ray_in_world(Eigen::Vector2d(u, v))).has_value();
      return hit == (mask(u, v) == 255);
    };
    int checked = 0, wrong = 0, area = 0;
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        area += mask(u, v) == 255;
        const bool edge = (u + 1 < cam.width && mask(u + 1, v) != mask(u, v)) ||
                          (v + 1 < cam.height && mask(u, v + 1) != mask(u, v));
        if (edge) {
          for (int k = 0; k < 2; ++k) {
            const int uu = u + (k == 1 && u + 1 < cam.width), vv = v;
            wrong += !check(uu, vv);
            ++checked;
          }
        }
      }
    }
    std::uniform_int_distribution<int> U(0, cam.width - 1), V(0, cam.height - 1);
    for (int k = 0; k < 4000; ++k) {
      wrong += !check(U(rng), V(rng));
      ++checked;
    }
    EXPECT_EQ(wrong, 0) << cam.id << " frame " << frame << ": " << wrong << " of " << checked;
    EXPECT_GT(area, 500) << cam.id << " sees the actor";
  }
}

TEST(SimStudio, TrueMaskIsExactForRingCameras) {
  const SimulatedStudio studio = make();
  for (int64_t frame : {0, 140, 230, 330}) expect_exact_mask(studio, frame);
}

TEST(SimStudio, TrueMaskIsExactWithDistortionAndSkew) {
  std::vector<Camera> cams = ring_cameras({.count = 3});
  cams[0].distortion = Distortion::radial(-0.12, 0.03);
  cams[1].distortion = Distortion::opencv(0.05, -0.02, 0.001, -0.0005, 0.0);
  cams[2].intrinsics.skew = 2.0;
  cams[2].intrinsics.fy = cams[2].intrinsics.fx * 1.03;
  const SimulatedStudio studio = make({}, cams);
  for (int64_t frame : {25, 260}) expect_exact_mask(studio, frame);
}

TEST(SimStudio, DeterministicAndThreadIndependent) {
  StudioOptions one;
  one.threads = 1;
  const SimulatedStudio a = make(), b = make(one);
  std::vector<Image<Rgb8>> ia, ib;
  std::vector<Mask> ma, mb;
  a.render_all(77, &ia, &ma);
  b.render_all(77, &ib, &mb);
  ASSERT_EQ(ia.size(), 6u);
  for (int c = 0; c < 6; ++c) {
    EXPECT_EQ(ia[c].pixels(), ib[c].pixels());
    EXPECT_EQ(ma[c].pixels(), mb[c].pixels());
    Image<Rgb8> single;
    a.render(c, 77, &single, nullptr);
    EXPECT_EQ(single.pixels(), ia[c].pixels());
  }
  // Noise changes from frame to frame (same actor pose is not required for this).
  Image<Rgb8> f78;
  a.render(0, 78, &f78, nullptr);
  EXPECT_NE(f78.pixels(), ia[0].pixels());
}

TEST(SimStudio, ActorStaysInEveryViewDuringTheSequence) {
  const SimulatedStudio studio = make();
  std::vector<Mask> masks;
  for (int64_t frame = 0; frame < 16 * 25; frame += 20) {
    studio.render_all(frame, nullptr, &masks);
    for (int c = 0; c < studio.camera_count(); ++c) {
      const Mask& m = masks[c];
      int border = 0;
      for (int x = 0; x < m.width(); ++x) border += m(x, 0) + m(x, m.height() - 1);
      for (int y = 0; y < m.height(); ++y) border += m(0, y) + m(m.width() - 1, y);
      EXPECT_EQ(border, 0) << studio.cameras()[c].id << " frame " << frame;
    }
  }
}

TEST(SimStudio, BackgroundIsKeyableBlueAndTheActorIsNot) {
  const SimulatedStudio studio = make();
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  for (int64_t frame : {10, 300}) {
    studio.render_all(frame, &images, &masks);
    for (int c = 0; c < studio.camera_count(); ++c) {
      long bg = 0, bg_blue = 0, fg = 0, fg_blue = 0;
      for (int y = 0; y < images[c].height(); ++y) {
        for (int x = 0; x < images[c].width(); ++x) {
          const Rgb8 p = images[c](x, y);
          const bool blue = p.b > p.r + 60 && p.b > p.g + 60;
          if (interior(masks[c], x, y, 0)) {
            ++bg;
            bg_blue += blue;
          } else if (interior(masks[c], x, y, 255)) {
            ++fg;
            fg_blue += blue;
          }
        }
      }
      EXPECT_GT(double(bg_blue) / bg, 0.999) << studio.cameras()[c].id;
      EXPECT_LT(double(fg_blue) / fg, 0.01) << studio.cameras()[c].id;
    }
  }
}

TEST(SimStudio, SensorNoiseHasTheRequestedSigma) {
  StudioOptions o;
  o.noise_sigma = 3.0;
  const SimulatedStudio studio = make(o, ring_cameras({.count = 1, .overhead = false}));
  Image<Rgb8> img;
  Mask mask;
  studio.render(0, 5, &img, &mask);
  double sum = 0, sum2 = 0;
  long n = 0;
  for (int y = 0; y < img.height(); ++y) {
    for (int x = 0; x < img.width(); ++x) {
      if (!interior(mask, x, y, 0) || y > img.height() / 2) continue;  // upper half: no shadow
      const double d = double(img(x, y).g) - studio.background(0)(x, y).g;
      sum += d;
      sum2 += d * d;
      ++n;
    }
  }
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(sigma, 3.0, 0.2);
}

TEST(SimStudio, ShadowDarkensTheFloorNearTheFeetOnly) {
  StudioOptions quiet;
  quiet.noise_sigma = 0;
  StudioOptions dark = quiet;
  dark.shadow = 0;
  const SimulatedStudio with = make(quiet), without = make(dark);
  Image<Rgb8> a, b;
  Mask ma;
  with.render(5, 40, &a, &ma);  // overhead camera sees the floor around the actor
  without.render(5, 40, &b, nullptr);
  long darker = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    if (ma.pixels()[i]) continue;
    ASSERT_LE(a.pixels()[i].b, b.pixels()[i].b);
    darker += a.pixels()[i].b + 20 < b.pixels()[i].b;
  }
  EXPECT_GT(darker, 300) << "a visible shadow";
  EXPECT_LT(darker, 40000) << "a shadow, not a dark floor";
}

// The patterned costume (StudioOptions::patterned_costume) is on the clothing's surface: a surface
// point seen by two cameras is darkened by the same factor in both (against the plain costume),
// the clothing varies, the skin (head) keeps its colour, the true mask is the plain one's.
TEST(SimStudio, PatternedCostumeIsTheSameOnTheSurfaceFromEveryCamera) {
  StudioOptions plain;
  plain.noise_sigma = 0;
  plain.antialias = false;
  StudioOptions patterned = plain;
  patterned.patterned_costume = true;
  const SimulatedStudio a = make(plain), b = make(patterned);
  const int64_t frame = 30;
  const FrameTruth truth = a.truth(frame);
  const int n = a.camera_count();
  std::vector<Image<Rgb8>> ia(n), ib(n);
  std::vector<Mask> ma(n), mb(n);
  for (int c = 0; c < n; ++c) {
    a.render(c, frame, &ia[c], &ma[c]);
    b.render(c, frame, &ib[c], &mb[c]);
    EXPECT_TRUE(std::equal(ma[c].data(), ma[c].data() + std::size_t(ma[c].width()) * ma[c].height(),
                           mb[c].data()))
        << c;
  }
  // Displayed patterned / plain (green: the least spill and ring light), at a pixel.
  auto ratio = [&](int c, int u, int v) { return double(ib[c](u, v).g) / double(ia[c](u, v).g); };
  std::mt19937_64 rng(7);
  int pairs = 0, skin = 0, skin_same = 0;
  double worst = 0, lo = 1, hi = 0;
  for (int tries = 0; tries < 200000 && pairs < 300; ++tries) {
    const int c0 = int(rng() % n), c1 = (c0 + 1) % n;
    const Camera& k0 = a.cameras()[c0];
    const Camera& k1 = a.cameras()[c1];
    const int u = int(rng() % k0.width), v = int(rng() % k0.height);
    if (!interior(ma[c0], u, v, 255) || ia[c0](u, v).g < 40) continue;
    const auto hit = truth.body.ray_hit(k0.centre_in_world(),
                                        k0.pixel_ray_in_world(Eigen::Vector2d(u, v)));
    if (!hit) continue;
    const bool is_skin = truth.body.parts[hit->part].id == PartId::head;
    if (is_skin) {
      ++skin;
      skin_same += ratio(c0, u, v) == 1.0;
      continue;
    }
    Eigen::Vector2d px;
    if (!k1.project(hit->point, &px)) continue;
    const int u1 = int(std::lround(px.x())), v1 = int(std::lround(px.y()));
    if (u1 < 2 || v1 < 2 || u1 >= k1.width - 2 || v1 >= k1.height - 2) continue;
    if (!interior(ma[c1], u1, v1, 255) || ia[c1](u1, v1).g < 40) continue;
    // Seen by both (nothing nearer on camera 1's ray), facing both: the same surface point up to
    // half a pixel.
    const auto hit1 = truth.body.ray_hit(k1.centre_in_world(),
                                         k1.pixel_ray_in_world(Eigen::Vector2d(u1, v1)));
    if (!hit1 || (hit1->point - hit->point).norm() > 0.004) continue;
    const double r0 = ratio(c0, u, v), r1 = ratio(c1, u1, v1);
    worst = std::max(worst, std::abs(r0 - r1));
    lo = std::min(lo, r0), hi = std::max(hi, r0);
    ++pairs;
  }
  std::printf("%d surface points seen by two cameras: patterned / plain %.2f .. %.2f, worst "
              "difference between the cameras %.3f; head: %d of %d pixels unchanged\n",
              pairs, lo, hi, worst, skin_same, skin);
  ASSERT_GE(pairs, 100);
  EXPECT_LT(worst, 0.08);           // the same surface point, the same factor
  EXPECT_GT(hi - lo, 0.15);         // a pattern, not a uniform darkening
  EXPECT_GT(lo, 0.6);               // within its range (0.6 .. 1, displayed: ^(1/2.2))
  EXPECT_GT(skin, 0);
  EXPECT_EQ(skin_same, skin);       // skin as before
}

TEST(SimStudio, SpillTintsActorEdgesBlue) {
  StudioOptions o;
  o.noise_sigma = 0;
  o.antialias = false;
  StudioOptions none = o;
  none.spill = 0;
  none.ring_light = 0;
  const SimulatedStudio with = make(o), without = make(none);
  Image<Rgb8> a, b;
  Mask m;
  with.render(0, 0, &a, &m);
  without.render(0, 0, &b, nullptr);
  long edge = 0, bluer = 0;
  for (int y = 1; y + 1 < m.height(); ++y) {
    for (int x = 1; x + 1 < m.width(); ++x) {
      if (m(x, y) != 255 || (m(x - 1, y) && m(x + 1, y) && m(x, y - 1) && m(x, y + 1))) continue;
      ++edge;
      bluer += a(x, y).b - a(x, y).r > b(x, y).b - b(x, y).r + 10;
    }
  }
  EXPECT_GT(double(bluer) / edge, 0.5) << bluer << " of " << edge;
}

TEST(SimStudio, MotionBlurSmearsTheImageButNotTheMask) {
  StudioOptions sharp;
  sharp.noise_sigma = 0;
  StudioOptions blurred = sharp;
  blurred.motion_blur = true;
  blurred.shutter = 1.0;
  const SimulatedStudio a = make(sharp), b = make(blurred);
  Image<Rgb8> ia, ib;
  Mask ma, mb;
  a.render(1, 60, &ia, &ma);  // walking
  b.render(1, 60, &ib, &mb);
  EXPECT_EQ(ma.pixels(), mb.pixels());
  long changed = 0;
  for (std::size_t i = 0; i < ia.pixels().size(); ++i) changed += !(ia.pixels()[i] == ib.pixels()[i]);
  EXPECT_GT(changed, 200);
}

// The true matte: 255 inside, 0 outside, fractions of the 16 sub-samples only where the
// silhouette crosses a pixel; cut at 1/2 it is the true mask up to sub-pixel ties.
TEST(SimStudio, TrueMatteIsTheSubSampleCoverage) {
  const SimulatedStudio studio = make();
  std::vector<Mask> masks, mattes;
  studio.render_all(40, nullptr, &masks, &mattes);
  for (int c = 0; c < studio.camera_count(); ++c) {
    const Mask& m = masks[c];
    const Mask& a = mattes[c];
    ASSERT_EQ(a.width(), m.width());
    long edge = 0, partial = 0, disagree = 0, area = 0;
    for (int y = 1; y + 1 < m.height(); ++y)
      for (int x = 1; x + 1 < m.width(); ++x) {
        const uint8_t v = a(x, y);
        const int k = (v * 16 + 127) / 255;
        ASSERT_EQ(v, (255 * k + 8) / 16) << "a multiple of 1/16 at " << x << "," << y;
        area += m(x, y) != 0;
        disagree += (v >= 128) != (m(x, y) != 0);
        const bool uniform = m(x - 1, y) == m(x, y) && m(x + 1, y) == m(x, y) &&
                             m(x, y - 1) == m(x, y) && m(x, y + 1) == m(x, y);
        if (uniform) {
          ASSERT_EQ(v, m(x, y)) << "away from the silhouette the matte is the mask";
          continue;
        }
        ++edge;
        partial += v != 0 && v != 255;
      }
    if (area == 0) continue;
    EXPECT_GT(double(partial) / edge, 0.4) << "camera " << c;
    EXPECT_LT(double(disagree) / area, 0.01) << "camera " << c;
  }
}

// Edge pixels mix actor and backing by area: the image of an edge pixel lies between its
// neighbours' colours in proportion to the matte (checked on the blue channel, where the
// backing and the actor differ most; no noise, no spill).
TEST(SimStudio, EdgePixelsMixActorAndBackingByCoverage) {
  StudioOptions o;
  o.noise_sigma = 0;
  o.spill = 0;
  const SimulatedStudio studio = make(o);
  Image<Rgb8> im;
  Mask m, a;
  studio.render(0, 40, &im, &m, &a);
  const Image<Rgb8>& bg = studio.background(0);
  long checked = 0, close = 0;
  for (int y = 2; y + 2 < m.height(); ++y)
    for (int x = 2; x + 2 < m.width(); ++x) {
      // Horizontal edges only: actor at x - 1 and x - 2, backing at x + 1 and x + 2.
      if (!(a(x - 2, y) == 255 && a(x - 1, y) == 255 && a(x + 1, y) == 0 && a(x + 2, y) == 0))
        continue;
      const double c = a(x, y) / 255.0;
      const double actor = im(x - 1, y).b, back = bg(x, y).b;
      if (std::abs(actor - back) < 60) continue;
      ++checked;
      close += std::abs(im(x, y).b - (c * actor + (1 - c) * back)) < 0.2 * std::abs(actor - back);
    }
  ASSERT_GT(checked, 30);
  EXPECT_GT(double(close) / checked, 0.85) << close << " of " << checked;
}

// With motion blur (and antialias, the default) the matte smears with the motion and still holds
// the actor's area: summed over the image it is the coverage integrated over the shutter.
TEST(SimStudio, MotionBlurredMatteKeepsTheArea) {
  StudioOptions o;
  o.motion_blur = true;
  const SimulatedStudio studio = make(o);
  Mask m, a;
  studio.render(1, 60, nullptr, &m, &a);
  double area = 0, matte = 0;
  long partial = 0;
  for (std::size_t i = 0; i < m.pixels().size(); ++i) {
    area += m.pixels()[i] != 0;
    matte += a.pixels()[i] / 255.0;
    partial += a.pixels()[i] != 0 && a.pixels()[i] != 255;
  }
  EXPECT_NEAR(matte / area, 1.0, 0.03);
  EXPECT_GT(partial, 300);
}

TEST(SimStudio, ProjectedImageAppearsFaintlyOnTheBackWall) {
  StudioOptions plain;
  StudioOptions projected;
  projected.projected_image = true;
  const SimulatedStudio a = make(plain), b = make(projected);
  // cam0 sits at +z and looks at the back wall z = -half_width.
  long changed = 0, still_blue = 0;
  for (std::size_t i = 0; i < a.background(0).pixels().size(); ++i) {
    const Rgb8 p = a.background(0).pixels()[i], q = b.background(0).pixels()[i];
    if (p == q) continue;
    ++changed;
    still_blue += q.b > q.r + 40 && q.b > q.g + 40;
  }
  EXPECT_GT(changed, 20000);
  EXPECT_GT(double(still_blue) / changed, 0.95) << "faint: the cloth stays keyable";
}

TEST(SimStudio, HeadCentreProjectsInsideTheMask) {
  const SimulatedStudio studio = make();
  std::vector<Mask> masks;
  for (int64_t frame : {0, 150, 270, 350}) {
    const FrameTruth truth = studio.render_all(frame, nullptr, &masks);
    for (int c = 0; c < studio.camera_count(); ++c) {
      Eigen::Vector2d px;
      ASSERT_TRUE(studio.cameras()[c].project(truth.head_centre(), &px));
      EXPECT_EQ(masks[c](int(std::lround(px.x())), int(std::lround(px.y()))), 255);
    }
  }
}

// A camera's colour response (StudioOptions::camera_response) is a linear gain per channel on
// everything it sees: in display values g^(1/2.2), on the cloth and on the actor alike (the actor's
// interior and the background away from the silhouette, noise off), other cameras untouched,
// the true mask unchanged.
TEST(SimStudio, CameraResponseScalesWhatThatCameraSees) {
  StudioOptions flat;
  flat.noise_sigma = 0;
  StudioOptions tinted = flat;
  tinted.camera_response.assign(6, {1, 1, 1});
  tinted.camera_response[2] = {1.2, 0.9, 0.8};
  const SimulatedStudio a = make(flat), b = make(tinted);
  for (int c : {1, 2}) {
    Image<Rgb8> ia, ib;
    Mask ma, mb;
    a.render(c, 30, &ia, &ma);
    b.render(c, 30, &ib, &mb);
    ASSERT_EQ(ma.pixels(), mb.pixels());
    const std::array<double, 3> g = tinted.camera_response[std::size_t(c)];
    double worst[2] = {0, 0};  // background, actor: |measured - expected| grey levels
    int counted[2] = {0, 0};
    for (int y = 0; y < ia.height(); ++y)
      for (int x = 0; x < ia.width(); ++x) {
        const bool actor = interior(ma, x, y, 255);
        if (!actor && !interior(ma, x, y, 0)) continue;
        const uint8_t* p = &ia(x, y).r;
        const uint8_t* q = &ib(x, y).r;
        for (int k = 0; k < 3; ++k) {
          if (p[k] < 8 || p[k] > 200) continue;  // rounding dominates; clipped
          const double expected = p[k] * std::pow(g[std::size_t(k)], 1 / 2.2);
          worst[actor] = std::max(worst[actor], std::abs(q[k] - expected));
          ++counted[actor];
        }
      }
    EXPECT_GT(counted[0], 10000) << c;
    EXPECT_GT(counted[1], 1000) << c;
    // Rounding of the 8-bit values (the background's, then the floor shadow's on it) and of the
    // gamma table (1/1024 of linear light).
    EXPECT_LE(worst[0], c == 2 ? 1.6 : 0.0) << "camera " << c << " background";
    EXPECT_LE(worst[1], c == 2 ? 3.0 : 0.0) << "camera " << c << " actor";
    if (c == 2) {
      long brighter_red = 0, darker_blue = 0, n = 0;
      for (int y = 0; y < ia.height(); ++y)
        for (int x = 0; x < ia.width(); ++x)
          if (interior(ma, x, y, 255)) {
            ++n;
            brighter_red += ib(x, y).r > ia(x, y).r;
            darker_blue += ib(x, y).b < ia(x, y).b;
          }
      EXPECT_GT(brighter_red, n * 9 / 10);
      EXPECT_GT(darker_blue, n * 9 / 10);
    }
  }
  // The draw: one entry per camera, deterministic, within the spreads.
  const auto r = random_camera_response(9, 7, 0.1, 0.04);
  ASSERT_EQ(r.size(), 9u);
  EXPECT_EQ(r, random_camera_response(9, 7, 0.1, 0.04));
  EXPECT_NE(r, random_camera_response(9, 8, 0.1, 0.04));
  for (const auto& g : r) {
    EXPECT_GE(g[1], 0.9);
    EXPECT_LE(g[1], 1.1);
    EXPECT_GE(g[0] / g[1], 0.96);
    EXPECT_LE(g[2] / g[1], 1.04);
  }
  // The balance's truth: display factors to the geometric mean (here of two cameras).
  const auto bal = balancing_gains({{1.21, 1, 0.81}, {1, 1, 1}});
  ASSERT_EQ(bal.size(), 2u);
  EXPECT_NEAR(bal[0][0], std::pow(1.1 / 1.21, 1 / 2.2), 1e-12);
  EXPECT_NEAR(bal[1][0], std::pow(1.1, 1 / 2.2), 1e-12);
  EXPECT_NEAR(bal[0][1], 1, 1e-12);
  EXPECT_NEAR(bal[0][2] * bal[1][2], 1, 1e-12);
  StudioOptions bad;
  bad.camera_response.assign(5, {1, 1, 1});  // 6 cameras
  auto r5 = SimulatedStudio::create(ring_cameras(), bad);
  ASSERT_FALSE(r5);
  EXPECT_NE(r5.error().message.find("camera_response"), std::string::npos);
  bad.camera_response.assign(6, {1, 0, 1});
  EXPECT_FALSE(SimulatedStudio::create(ring_cameras(), bad));
}

TEST(SimStudio, RejectsBadConfigurationWithOneLine) {
  EXPECT_FALSE(SimulatedStudio::create({}, {}));
  StudioOptions o;
  o.spill = 2;
  auto r = SimulatedStudio::create(ring_cameras(), o);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  std::vector<Camera> cams = ring_cameras({.count = 1});
  cams[0].intrinsics.fx = 0;
  EXPECT_FALSE(SimulatedStudio::create(cams, {}));
  cams = ring_cameras({.count = 1});
  cams[0].width = 0;
  EXPECT_FALSE(SimulatedStudio::create(cams, {}));
  for (int samples : {1, 65}) {
    StudioOptions bad;
    bad.aa_samples = samples;
    auto aa = SimulatedStudio::create(ring_cameras(), bad);
    ASSERT_FALSE(aa);
    EXPECT_NE(aa.error().message.find("aa_samples"), std::string::npos);
  }
}

}  // namespace
}  // namespace studio::sim

// Keying with the projectors on (issue 15): two projectors show a bright, saturated scene on the
// cloth (the back wall and a side wall); the studio cameras see it dimmed by the retro-reflective
// cloth on top of their own LED ring's blue (sim/projector_light.h (c)), with every realism knob of
// keyer_sim_test on. The chroma keyer must still reach IoU >= 0.98 against the simulator's true
// masks (the true matte cut at 1/2), and lose at most 0.005 IoU against the same frames with the
// projectors off (the positive control).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "keyer/keyer.h"
#include "sim/cameras.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "support/masks.h"

namespace studio::keyer {
namespace {

// A projected "scene": sky gradient, a white sun, green and red ground bands, a yellow
// chequered floor and saturated stripes of every primary (blue and green included).
Image<Rgb8> scene_frame(int w, int h, int variant) {
  Image<Rgb8> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Rgb8 c;
      const double v = double(y) / h;
      if (v < 0.55) {
        c = {uint8_t(90 + 120 * v), uint8_t(150 + 80 * v), 250};
        const double dx = x - w * (0.7 - 0.2 * variant), dy = y - 0.2 * h;
        if (dx * dx + dy * dy < 0.01 * w * w) c = {255, 255, 255};
      } else if (v < 0.65) {
        c = (x / 97) % 3 == 0   ? Rgb8{250, 30, 20}
            : (x / 97) % 3 == 1 ? Rgb8{20, 240, 40}
                                : Rgb8{30, 40, 250};
      } else {
        c = ((x / 120 + y / 90) % 2) ? Rgb8{240, 220, 60} : Rgb8{70, 150, 50};
      }
      img(x, y) = c;
    }
  return img;
}

sim::StudioOptions options(bool projectors) {
  sim::StudioOptions o;
  o.projected_image = false;  // the legacy faint picture: replaced by real projectors here
  if (!projectors) return o;
  const sim::Cyclorama cyc;
  sim::SimProjector back{sim::studio_projector(cyc, {0.5, 2.5, 3.8}, 6.0, 1280, 720), {}};
  back.frame = scene_frame(1280, 720, 0);
  // A second projector on the left wall (x = -4.5), from the right.
  sim::SimProjector side{
      sim::studio_projector(cyc, {3.8, 2.5, 0.3}, 6.0, 1280, 720, {-4.5, 1.4, 0}, "proj1"), {}};
  side.frame = scene_frame(1280, 720, 1);
  o.projector_light.projectors = {back, side};
  return o;
}

double mean_iou(bool projectors, int* masks) {
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), options(projectors));
  EXPECT_TRUE(studio) << studio.error().message;
  auto keyer = Keyer::create(KeyerOptions{});
  EXPECT_TRUE(keyer);
  if (!studio || !keyer) return 0;
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> silhouettes;
  std::vector<Image<uint8_t>> mattes;
  RunMask mask;
  double sum = 0, worst = 1;
  *masks = 0;
  for (int64_t frame = 0; frame < 200; frame += 25) {
    studio->render_all(frame, &images, &silhouettes, &mattes);
    for (int c = 0; c < studio->camera_count(); ++c) {
      if (std::none_of(silhouettes[c].pixels().begin(), silhouettes[c].pixels().end(),
                       [](uint8_t v) { return v != 0; }))
        continue;
      EXPECT_TRUE(keyer->key(images[c].view(), mask));
      Mask truth = mattes[c];
      for (uint8_t& v : truth.pixels()) v = v >= 128 ? 255 : 0;
      const double i = support::iou(mask.to_mask(), truth);
      sum += i;
      worst = std::min(worst, i);
      ++*masks;
    }
  }
  std::printf("projectors %s: %d masks, mean IoU %.4f, worst %.4f\n", projectors ? "on" : "off",
              *masks, sum / *masks, worst);
  return sum / *masks;
}

TEST(KeyerProjectorsOn, StillReachesTheTrueMasks) {
  // The projected light really is in the images: the cloth's colour changes where it falls.
  auto on = sim::SimulatedStudio::create(sim::ring_cameras(), options(true));
  auto off = sim::SimulatedStudio::create(sim::ring_cameras(), options(false));
  ASSERT_TRUE(on && off);
  long changed = 0;
  const auto& a = on->background(0).pixels();
  const auto& b = off->background(0).pixels();
  for (std::size_t i = 0; i < a.size(); ++i)
    changed += std::abs(int(a[i].r) - int(b[i].r)) + std::abs(int(a[i].g) - int(b[i].g)) > 20;
  EXPECT_GT(changed, long(a.size() / 10));

  int masks_on = 0, masks_off = 0;
  const double iou_on = mean_iou(true, &masks_on);
  const double iou_off = mean_iou(false, &masks_off);
  EXPECT_GE(masks_on, 30);
  EXPECT_GE(iou_on, 0.98);
  EXPECT_GE(iou_on, iou_off - 0.005);
}

}  // namespace
}  // namespace studio::keyer

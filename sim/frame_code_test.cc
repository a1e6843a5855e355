// The actor-worn frame code (sim/frame_code.h): read back from the simulated cameras' images at
// the bands' projected centres, it gives the frame number mod 81 for every camera and frame;
// the plain actor (frame_code off) decodes to nothing; the keyer's blue rule keeps the bands.
#include "sim/frame_code.h"

#include <gtest/gtest.h>

#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::sim {
namespace {

// Digits read at the band centres facing camera `cam` (mean of a 3x3 window), -1 where the band
// centre is hidden by another part or outside the image.
std::vector<int> read_digits(const SimulatedStudio& studio, int cam, int64_t frame,
                             const Image<Rgb8>& image) {
  const Camera& c = studio.cameras()[cam];
  const FrameTruth truth = studio.truth(frame);
  const Eigen::Vector3d eye = c.centre_in_world();
  std::vector<int> digits;
  for (int b = 0; b < frame_code::kBands; ++b) {
    const Eigen::Vector3d x = frame_code::band_point(truth.body, b, eye);
    const auto hit = truth.body.ray_hit(eye, (x - eye).normalized());
    Eigen::Vector2d pix;
    const bool in_front = c.project(x, &pix);
    const Eigen::Vector2d* px = &pix;
    if (!hit || hit->part != int(PartId::torso) || (hit->point - x).norm() > 0.01 || !in_front ||
        px->x() < 2 || px->y() < 2 || px->x() > c.width - 3 || px->y() > c.height - 3) {
      digits.push_back(-1);
      continue;
    }
    double sum[3] = {0, 0, 0};
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Rgb8 p = image(int(std::lround(px->x())) + dx, int(std::lround(px->y())) + dy);
        sum[0] += p.r;
        sum[1] += p.g;
        sum[2] += p.b;
      }
    digits.push_back(frame_code::classify(sum[0] / 9, sum[1] / 9, sum[2] / 9));
  }
  return digits;
}

TEST(FrameCode, DigitsAndDecodeAreInverse) {
  for (int64_t f : {0, 1, 2, 3, 80, 81, 82, 1234, 99999}) {
    std::vector<int> d;
    for (int b = 0; b < frame_code::kBands; ++b) d.push_back(frame_code::digit(f, b));
    EXPECT_EQ(frame_code::decode(d), int(f % 81)) << f;
  }
  EXPECT_FALSE(frame_code::decode(std::vector<int>{0, 1, -1, 2}));
  EXPECT_EQ(frame_code::band_of(frame_code::kLow - 0.01), -1);
  EXPECT_EQ(frame_code::band_of(frame_code::kHigh), -1);
  // The three colours classify as themselves under any lighting level, never as the cloth.
  for (int d = 0; d < 3; ++d)
    for (double light : {0.3, 0.6, 1.0}) {
      const Albedo a = frame_code::albedo(d);
      auto disp = [&](float x) { return 255 * std::pow(x * light, 1 / 2.2); };
      EXPECT_EQ(frame_code::classify(disp(a.r), disp(a.g), disp(a.b)), d) << d << " " << light;
      EXPECT_LT(a.b, a.r + a.g) << "no blue: the keyer keeps the bands";
    }
  EXPECT_EQ(frame_code::classify(30, 66, 212), -1);  // the cloth
}

TEST(FrameCode, BandPointsLieInTheirBandAtEveryHeight) {
  auto studio = SimulatedStudio::create(ring_cameras({})).value();
  const FrameTruth truth = studio.truth(40);
  const Part& torso = truth.body.part(PartId::torso);
  const Eigen::Vector3d eye(1.0, 1.6, 4.0);
  for (int b = 0; b < frame_code::kBands; ++b)
    for (double along : {0.05, 0.25, 0.5, 0.75, 0.95}) {
      const Eigen::Vector3d x = frame_code::band_point(truth.body, b, eye, along);
      const Eigen::Vector3d u =
          (torso.axes.transpose() * (x - torso.centre)).cwiseQuotient(torso.radii);
      EXPECT_NEAR(u.norm(), 1.0, 1e-9) << "on the torso's surface";
      EXPECT_EQ(frame_code::band_of(u.y()), b) << b << " at " << along;
    }
  // The default is the centre.
  EXPECT_TRUE(frame_code::band_point(truth.body, 1, eye)
                  .isApprox(frame_code::band_point(truth.body, 1, eye, 0.5)));
}

TEST(FrameCode, ReadsBackFromEveryCameraImage) {
  RingOptions ring;
  ring.count = 5;
  StudioOptions options;
  options.frame_code = true;
  auto studio = SimulatedStudio::create(ring_cameras(ring), options).value();
  int decoded = 0, tried = 0;
  for (int64_t f = 0; f < 400; f += 37) {
    for (int cam = 0; cam < 4; ++cam) {  // the ring cameras (4 is overhead)
      Image<Rgb8> image;
      studio.render(cam, f, &image, nullptr);
      const auto digits = read_digits(studio, cam, f, image);
      ++tried;
      const auto v = frame_code::decode(digits);
      if (!v) continue;  // a band hidden by an arm
      ++decoded;
      EXPECT_EQ(*v, int(f % 81)) << "frame " << f << " camera " << cam;
    }
  }
  EXPECT_GE(decoded, tried * 3 / 4) << decoded << " of " << tried;
  // Negative control: the plain shirt carries no code.
  auto plain = SimulatedStudio::create(ring_cameras(ring), {}).value();
  Image<Rgb8> image;
  int plain_decoded = 0;
  for (int64_t f = 0; f < 400; f += 37) {
    plain.render(0, f, &image, nullptr);
    plain_decoded += frame_code::decode(read_digits(plain, 0, f, image)).has_value();
  }
  EXPECT_EQ(plain_decoded, 0);
}

}  // namespace
}  // namespace studio::sim

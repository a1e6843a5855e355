// The clean-plate state machine (keyer/plate_keyer.h) shared by the keyer node and the capture
// node: plate capture on command, frames unkeyed without a plate (said once), clearing, refusals.
#include "keyer/plate_keyer.h"

#include <gtest/gtest.h>

namespace studio::keyer {
namespace {

using Step = PlateKeyer::Step;

// A grey backing, and the same with a bright 20x16 "actor" at (10, 8).
Image<Rgb8> backing(int w, int h) {
  Image<Rgb8> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img(x, y) = Rgb8{90, 95, 100};
  return img;
}
Image<Rgb8> with_actor(int w, int h) {
  Image<Rgb8> img = backing(w, h);
  for (int y = 8; y < 24; ++y)
    for (int x = 10; x < 30; ++x) img(x, y) = Rgb8{230, 180, 40};
  return img;
}

PlateKeyer difference_keyer() {
  KeyerOptions o;
  o.mode = KeyMode::kDifference;
  o.edge_refine = false;
  o.cleanup.min_component_area = 0;
  o.cleanup.max_hole_area = 0;
  return PlateKeyer(Keyer::create(o).value());
}

TEST(PlateKeyer, DifferenceKeyWaitsForAPlateCapturedOnCommand) {
  PlateKeyer k = difference_keyer();
  const Image<Rgb8> plate = backing(64, 48), actor = with_actor(64, 48);
  RunMask mask;
  auto r = k.frame(actor.view(), mask);
  EXPECT_EQ(r.step, Step::kNoPlate);
  EXPECT_TRUE(r.first);
  r = k.frame(actor.view(), mask);
  EXPECT_EQ(r.step, Step::kNoPlate);
  EXPECT_FALSE(r.first);  // said once

  k.request(2);
  EXPECT_EQ(k.frame(plate.view(), mask).step, Step::kPlateFrame);
  EXPECT_TRUE(k.capturing());
  EXPECT_EQ(k.frame(plate.view(), mask).step, Step::kPlateCaptured);
  EXPECT_FALSE(k.capturing());
  EXPECT_EQ(k.keyer().plate_frames(), 2);

  r = k.frame(actor.view(), mask);
  ASSERT_EQ(r.step, Step::kKeyed) << r.error.message;
  EXPECT_EQ(mask.area(), 20u * 16u);
  EXPECT_TRUE(mask.contains(15, 10));
  EXPECT_FALSE(mask.contains(40, 30));

  // KeyerPlate 0: cleared with the next frame, which is then unkeyed (and said again).
  k.request(0);
  r = k.frame(actor.view(), mask);
  EXPECT_TRUE(r.cleared);
  EXPECT_EQ(r.step, Step::kNoPlate);
  EXPECT_TRUE(r.first);
  EXPECT_FALSE(k.keyer().has_plate());
}

TEST(PlateKeyer, RefusedFramesAndTheNewestRequestWins) {
  PlateKeyer k = difference_keyer();
  const Image<Rgb8> plate = backing(64, 48), small = backing(32, 24);
  RunMask mask;
  k.request(5);
  k.request(2);  // replaces the 5 before any frame took it
  EXPECT_EQ(k.frame(plate.view(), mask).step, Step::kPlateFrame);
  auto r = k.frame(small.view(), mask);  // another size than the plate's first frame
  EXPECT_EQ(r.step, Step::kRefused);
  EXPECT_FALSE(r.error.message.empty());
  EXPECT_EQ(k.frame(plate.view(), mask).step, Step::kPlateCaptured);  // the capture carried on
  r = k.frame(small.view(), mask);  // a frame whose size differs from the plate's
  EXPECT_EQ(r.step, Step::kRefused);
  EXPECT_FALSE(r.error.message.empty());
}

TEST(PlateKeyer, ChromaKeyKeysAtOnceAndCanStillTakeAPlate) {
  PlateKeyer k(Keyer::create(KeyerOptions{}).value());
  const Image<Rgb8> frame = backing(64, 48);
  RunMask mask;
  EXPECT_EQ(k.frame(frame.view(), mask).step, Step::kKeyed);
  k.request(1);
  EXPECT_EQ(k.frame(frame.view(), mask).step, Step::kPlateCaptured);
  EXPECT_EQ(k.frame(frame.view(), mask).step, Step::kKeyed);
}

}  // namespace
}  // namespace studio::keyer

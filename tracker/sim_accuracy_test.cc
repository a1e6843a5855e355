// Accuracy of the head tracker on the simulated studio (issue 6): true masks of the 6-camera
// ring (sim/) → line-segment visual hull (hull/) → rasterise → head search, scored
// against the simulator's true head centre (the centre of the skull ellipsoid). Targets: head
// centre error <= 3 cm RMS for each scripted motion, and never the raised hand.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/run_mask.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "tracker/head_search.h"
#include "tracker/segment_raster.h"

namespace studio::tracker {
namespace {

struct Result {
  double rms = 0, worst = 0;
  double nearest_hand = 1e9;  // smallest distance of an estimate to the right hand
  int frames = 0, missed = 0;
};

// Frames [0, frames) every `step`, grid of `columns` columns over the acting area.
Result run(sim::Motion motion, int frames, int step, int columns = 128) {
  sim::StudioOptions so;
  so.actor.motion = motion;
  so.actor.seed = 5;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
  EXPECT_TRUE(studio.has_value());
  hull::GridSpec spec;
  spec.box_min = {-1.6, 0, -1.6};
  spec.box_max = {1.6, 2.6, 1.6};
  spec.axis = hull::Axis::y;
  spec.cells_u = spec.cells_v = columns;
  auto search = HeadSearch::create(HeadSearchOptions{}).value();
  Result r;
  double sum2 = 0;
  std::vector<Mask> masks;
  std::vector<RunMask> runs(std::size_t(studio->camera_count()));
  OccupancyGrid grid;
  for (int f = 0; f < frames; f += step) {
    const sim::FrameTruth truth = studio->render_all(f, nullptr, &masks);
    std::vector<hull::View> views;
    for (int c = 0; c < studio->camera_count(); ++c) {
      runs[std::size_t(c)] = RunMask::from_mask(masks[std::size_t(c)].view());
      views.push_back({&studio->cameras()[std::size_t(c)], &runs[std::size_t(c)]});
    }
    auto hull = hull::visual_hull(spec, views);
    EXPECT_TRUE(hull.has_value());
    rasterise(*hull, &grid);
    const auto heads = search.find(grid);
    ++r.frames;
    if (heads.empty()) {
      ++r.missed;
      continue;
    }
    const double e = (heads[0].position - truth.head_centre()).norm();
    sum2 += e * e;
    r.worst = std::max(r.worst, e);
    r.nearest_hand = std::min(
        r.nearest_hand, (heads[0].position - truth.body.part(sim::PartId::hand_r).centre).norm());
    if (std::getenv("TRACKER_VERBOSE"))
      std::printf(
          "frame %3d err %.3f est %.3f %.3f %.3f truth %.3f %.3f %.3f heads %zu conf %.2f\n", f, e,
          heads[0].position.x(), heads[0].position.y(), heads[0].position.z(),
          truth.head_centre().x(), truth.head_centre().y(), truth.head_centre().z(), heads.size(),
          heads[0].confidence);
  }
  r.rms = std::sqrt(sum2 / std::max(1, r.frames - r.missed));
  std::printf("%s: %d frames, head centre error %.1f mm RMS, worst %.1f mm, missed %d\n",
              sim::motion_name(motion), r.frames, r.rms * 1000, r.worst * 1000, r.missed);
  return r;
}

TEST(SimAccuracy, Walk) {
  const Result r = run(sim::Motion::walk, 125, 5);
  EXPECT_EQ(r.missed, 0);
  EXPECT_LE(r.rms, 0.03);
}

TEST(SimAccuracy, Turn) {
  const Result r = run(sim::Motion::turn, 75, 3);
  EXPECT_EQ(r.missed, 0);
  EXPECT_LE(r.rms, 0.03);
}

TEST(SimAccuracy, Crouch) {
  const Result r = run(sim::Motion::crouch, 100, 4);
  EXPECT_EQ(r.missed, 0);
  EXPECT_LE(r.rms, 0.03);
}

TEST(SimAccuracy, HandRaisedAboveTheHeadIsNeverTakenForIt) {
  const Result r = run(sim::Motion::raise_hand, 100, 4);
  EXPECT_EQ(r.missed, 0);
  EXPECT_LE(r.rms, 0.03);
  EXPECT_LT(r.worst, 0.08);  // every frame on the head, none on the hand
  EXPECT_GT(r.nearest_hand, 0.15);
}

}  // namespace
}  // namespace studio::tracker

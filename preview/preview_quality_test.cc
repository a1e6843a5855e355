// The textured actor against a held-out camera, in process and deterministic (issue 16 "quality
// against truth"; testing/held_out.h): the simulated studio (8 ring cameras + overhead,
// 352x288) renders each frame; the actor's true surface or the visual hull of the true masks
// (hull/ library, the node's grid 96 with exact crossings) is textured by ActorTexturer (gl/)
// from the pose of a held-out camera that feeds nothing, nearest camera and blend; PSNR over the
// union of the true and the rendered silhouette, pooled over 10 frames of the actor's sequence.
//
// What it shows: with the true geometry the blend reaches the 28 dB, far above nearest
// (one camera leaves what it cannot see grey); with the visual hull of these cameras the
// figure is bounded by the geometry, not by the texturing: the hull exceeds the body between
// cameras (a ring of cameras 45 degrees apart: by up to r (1 / cos 22.5 deg - 1) ~ 8 % of a
// limb's radius), every pixel of it costs the difference between the actor and the blue
// backing, and no key can carve it (the point is inside every camera's silhouette).
// preview_error_sources_test splits the error by region, effect and camera (BENCHMARKS.md).
#include <gtest/gtest.h>

#include <cstdio>

#include "testing/held_out.h"

namespace studio::preview::held_out {
namespace {

class PreviewQualityTest : public HeldOutTest {
 protected:
  // Nearest and blend over kFrames, printed with where the blend's error is.
  static std::pair<Breakdown, Breakdown> run(bool hull, bool every_mask = false) {
    Scoring s;
    s.hull = hull;
    s.carve_all_cameras = every_mask;
    s.verbose = true;
    const auto r =
        evaluate(s, {{"nearest", TextureMode::nearest}, {"blend", TextureMode::blend}}, kFrames);
    const char* what = !hull ? "true surface" : every_mask ? "hull, every mask" : "hull, keys only";
    std::printf("%s: nearest %s\n%s: blend   %s\n", what, r[0].line().c_str(), what,
                r[1].line().c_str());
    return {r[0], r[1]};
  }
};

// Measured 28.2 dB (nearest 18.0). Before the key threshold (actor_texturer.h key_threshold)
// 27.5: the silhouette test discarded surface points at every camera's rim.
TEST_F(PreviewQualityTest, WithTheTrueSurfaceTheBlendReaches28dB) {
  const auto [nearest, blend] = run(false);
  EXPECT_GT(blend.psnr(), nearest.psnr() + 5);
  EXPECT_GE(blend.psnr(), 28.0);
}

// Measured 20.8 dB (nearest 15.8): two thirds of the error is in pixels of one silhouette only,
// most of it the hull's excess (rendered where the held-out camera sees the backing). Carving
// against every camera's mask (the node's default, carve_masks; the image-based visual hull of
// all nine at their pixel resolution instead of the hull's 31 mm grid) as well as the three
// texturing cameras' keys: 21.1 dB, excess 2 899 -> 2 483 px, interior 25.8 -> 26.3 dB. The
// issue's 28 dB is out of reach of the visual hull of these cameras: docs/preview.md,
// preview_error_sources_test.
TEST_F(PreviewQualityTest, WithTheVisualHullTheBlendBeatsNearest) {
  const auto [nearest, keys] = run(true);
  const auto [nearest_too, blend] = run(true, true);
  EXPECT_GT(blend.psnr(), nearest.psnr() + 3);
  EXPECT_GE(blend.psnr(), 21.0);
  EXPECT_GT(blend.psnr(), keys.psnr() + 0.2);
  EXPECT_LT(blend.rendered_only.px, keys.rendered_only.px);
}

}  // namespace
}  // namespace studio::preview::held_out

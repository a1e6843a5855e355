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

#include "sim/studio.h"
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

// Cameras that differ as a real rig's do (exposure +-10 %, white balance +-5 %,
// sim::random_camera_response seed 3; the held-out camera's response is 1, 1, 1), the blend with
// the colour balance the node learns (preview/rig_balance.h, pooled over 8 earlier frames and
// the frames drawn) and without it. Measured (true surface): identical cameras 28.02 dB;
// differing 27.00 dB without, 27.70 with (interior 28.5 -> 29.8 dB); each camera brought to the
// held-out camera's response by its true gains 28.03 dB (the level of the whole rig, which no
// balance between cameras can know, is the rest). With the visual hull 20.95 -> 21.07 dB
// (interior 25.3 -> 25.9): the hull's excess dominates there.
// A camera's gains multiply its colours where it colours the actor (set_camera): the same view
// drawn with gains (0.5, 1, 1.25) and with none, pixel by pixel.
TEST_F(PreviewQualityTest, TheTexturerDrawsACamerasColoursTimesItsGains) {
  const Studio s = make_studio();
  sim::StudioOptions o;
  o.threads = 2;
  auto studio = sim::SimulatedStudio::create(s.cameras, o).value();
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  const sim::FrameTruth t = studio.render_all(100, &images, &masks);
  TexturerOptions to;
  to.inflate_m = 0;
  to.unseen = {1, 0, 1};  // shaded magenta: told apart from the camera's colours below
  auto texturer = ActorTexturer::create(to).value();
  ASSERT_TRUE(texturer.set_mesh(true_mesh(t.body)).has_value());
  auto target = scene_render::RenderTarget::create(kW, kH).value();
  auto draw = [&](const Eigen::Vector3f& gains) {
    EXPECT_TRUE(
        texturer
            .set_camera(0, s.cameras[0], reinterpret_cast<const uint8_t*>(images[0].data()), gains)
            .has_value());
    target.bind();
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    texturer.draw(s.view, TextureMode::nearest, {1, 0, 0});
    std::vector<uint8_t> rgba;
    target.read_rgba(rgba);
    return rgba;
  };
  const auto plain = draw(Eigen::Vector3f::Ones()), scaled = draw({0.5f, 1.0f, 1.25f});
  int textured = 0, off = 0;
  for (std::size_t i = 0; i < plain.size(); i += 4) {
    if (plain[i + 3] == 0) continue;
    if (plain[i + 1] == 0 && plain[i] == plain[i + 2]) continue;  // unseen by the camera
    ++textured;
    const double want[3] = {0.5 * plain[i], double(plain[i + 1]),
                            std::min(255.0, 1.25 * plain[i + 2])};
    for (int k = 0; k < 3; ++k)
      if (std::abs(scaled[i + std::size_t(k)] - want[k]) > 1.5) ++off;
  }
  EXPECT_GT(textured, 1000);
  EXPECT_EQ(off, 0);
  EXPECT_FALSE(texturer
                   .set_camera(0, s.cameras[0], reinterpret_cast<const uint8_t*>(images[0].data()),
                               {0.0f, 1.0f, 1.0f})
                   .has_value());
}

// Frames the balance pools before the scored ones (kFrames): a preview that has been running.
const std::vector<int64_t> kWarmup{10, 50, 90, 130, 180, 230, 280, 320};

TEST_F(PreviewQualityTest, TheColourBalanceRestoresTheBlendOfDifferingCameras) {
  const auto response = sim::random_camera_response(9, 3, 0.1, 0.05);
  std::vector<Breakdown> scores;
  std::vector<offline::ColourBalance> balances;
  for (const bool hull : {false, true})
    for (const bool balance : {false, true}) {
      Scoring s;
      s.hull = hull;
      s.carve_all_cameras = true;
      s.sim.camera_response = response;
      s.balance = balance;
      s.balances = &balances;
      s.balance_warmup = kWarmup;
      const Breakdown b = evaluate(s, {{"blend", TextureMode::blend}}, kFrames)[0];
      std::printf("%s, differing cameras, colour balance %s: %s\n", hull ? "hull" : "true surface",
                  balance ? "on " : "off", b.line().c_str());
      scores.push_back(b);
    }
  // The estimate against the truth: the linked cameras' gain ratios.
  const auto truth = sim::balancing_gains(response);
  const offline::ColourBalance& last = balances.back();
  ASSERT_TRUE(last.applied);
  double worst = 0;
  int linked = 0;
  for (std::size_t i = 0; i < last.estimated.size(); ++i)
    for (std::size_t j = i + 1; j < last.estimated.size(); ++j) {
      if (last.estimated[i] == Eigen::Vector3f::Ones() ||
          last.estimated[j] == Eigen::Vector3f::Ones())
        continue;
      ++linked;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(double(last.estimated[i][k] / last.estimated[j][k]) /
                                             (truth[i][std::size_t(k)] / truth[j][std::size_t(k)]) -
                                         1));
    }
  std::printf("colour balance: %d frames, %d pairs of linked cameras, worst ratio error %.2f %%\n",
              last.frames, linked, 100 * worst);
  EXPECT_GE(linked, 3);
  EXPECT_LT(worst, 0.01);                                                 // measured 0.44 %
  EXPECT_GT(scores[1].psnr(), scores[0].psnr() + 0.5);                    // measured +0.70 dB
  EXPECT_GT(scores[1].interior.psnr(), scores[0].interior.psnr() + 1.0);  // +1.3 dB
  EXPECT_GT(scores[3].interior.psnr(), scores[2].interior.psnr() + 0.3);  // +0.6 dB
}

// The control: on cameras that agree the balance estimates gains within its tolerance and draws
// exactly what it draws without it (measured: the final estimate within 0.5 % of 1; 3.7 % after
// the first 3 frames, which is why RigBalance waits for 8).
TEST_F(PreviewQualityTest, TheColourBalanceLeavesAgreeingCamerasAlone) {
  std::vector<offline::ColourBalance> balances;
  std::vector<Breakdown> scores;
  for (const bool balance : {false, true}) {
    Scoring s;
    s.hull = true;
    s.carve_all_cameras = true;
    s.balance = balance;
    s.balances = &balances;
    s.balance_warmup = kWarmup;
    scores.push_back(evaluate(s, {{"blend", TextureMode::blend}}, kFrames)[0]);
  }
  ASSERT_EQ(balances.size(), kWarmup.size() + kFrames.size());
  for (const offline::ColourBalance& b : balances) EXPECT_FALSE(b.applied);
  for (const Eigen::Vector3f& g : balances.back().estimated)
    EXPECT_LT((g.array() - 1).abs().maxCoeff(), 0.01f);
  EXPECT_GE(balances.back().pairs, 3);
  EXPECT_EQ(scores[1].total().squared, scores[0].total().squared);
  EXPECT_EQ(scores[1].total().px, scores[0].total().px);
}

// The node's rig samples (node/view_pipeline.h, balance_rig_every; what Match cameras sends):
// every camera's image of a frame pooled, not only the three the view textures from, so the
// estimate links the whole rig from any viewpoint. Against the truth on a differing rig, and on
// an agreeing one (the estimate's own error). Measured: one linked set of all 9 cameras from the
// first frame; after the 18 frames the worst pair ratio error 3.2 % on both rigs (the overhead
// camera's view-dependent bias: 2.6 % off on the agreeing rig, the ring cameras within 0.8 %),
// 7-10 % after the first frames.
TEST_F(PreviewQualityTest, TheColourBalancePooledFromEveryCameraLinksTheRig) {
  const auto response = sim::random_camera_response(9, 3, 0.1, 0.05);
  const auto truth = sim::balancing_gains(response);
  for (const bool differ : {true, false}) {
    std::vector<offline::ColourBalance> balances;
    Scoring s;
    s.hull = true;
    s.carve_all_cameras = true;
    if (differ) s.sim.camera_response = response;
    s.balance = true;
    s.balance_all_cameras = true;
    s.balances = &balances;
    s.balance_warmup = kWarmup;
    evaluate(s, {{"blend", TextureMode::blend}}, kFrames);
    ASSERT_EQ(balances.size(), kWarmup.size() + kFrames.size());
    for (const offline::ColourBalance& b : balances)
      for (int set : b.linked_set) EXPECT_EQ(set, 0) << "one linked set of every camera";
    // The worst pair ratio against the truth, before (the cameras as they are) and after.
    const offline::ColourBalance& last = balances.back();
    double before = 0, after = 0;
    for (std::size_t i = 0; i < last.estimated.size(); ++i)
      for (std::size_t j = i + 1; j < last.estimated.size(); ++j)
        for (int k = 0; k < 3; ++k) {
          const double t = differ ? truth[i][std::size_t(k)] / truth[j][std::size_t(k)] : 1.0;
          before = std::max(before, std::abs(t - 1));
          after = std::max(after,
                           std::abs(double(last.estimated[i][k] / last.estimated[j][k]) / t - 1));
        }
    std::printf(
        "%s rig, every camera pooled over %d frames: %d pairs, the worst camera pair "
        "%.2f %% apart, the estimate's worst pair ratio error %.2f %%\n",
        differ ? "differing" : "agreeing", last.frames, last.pairs, 100 * before, 100 * after);
    EXPECT_LT(after, 0.05);
    if (differ) EXPECT_GT(before, 0.1);
  }
}

}  // namespace
}  // namespace studio::preview::held_out

// Photo-consistent refinement and texture against the simulated studio's truth (issue 21): on
// concave poses (standing with the arms close to the body; crouching), 9 cameras (8 ring +
// overhead) at 704x576 and 256x256 columns, keyed with the keyer's blue defaults (so the blue
// spill is in the images and on the mask edges):
// - the refined surface is closer to the true actor than the visual hull (with exact crossings)
//   at the same resolution, pooled over both directions (mesh -> truth, truth -> mesh);
// - no frame is worse than the hull by more than one cell (mean or 95th percentile);
// - the textured refined mesh rendered from a held-out camera (between two ring cameras, lower)
//   reaches the PSNR below over the actor's interior (its true mask without the 2-pixel border)
//   and, rendered anti-aliased over that camera's clean plate, over the union of the true and
//   the rendered silhouettes (border and contour included: the measure);
// - the surface stage after carving (surface_refine.h: shape prior with rim anchors) is closer
//   still, and widens the union PSNR (the hull's bulges outside the true silhouette shrink);
// - the result does not depend on the thread count; bad input is refused by reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <tuple>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/photo_carve.h"
#include "offline/surface_refine.h"
#include "offline/texture.h"
#include "sim/cameras.h"
#include "testing/same_carve.h"
#include "testing/texture_oracle.h"
#include "testing/truth.h"

namespace studio::offline {
namespace {

constexpr int kGrid = 256;

std::vector<Camera> rig() {
  sim::RingOptions ring;
  ring.count = 9;  // 8 on the ring + overhead
  std::vector<Camera> cams = sim::ring_cameras(ring);
  sim::RingOptions held = ring;
  held.count = 8;
  held.overhead = false;
  held.first_azimuth_deg = 22.5;
  held.height_m = 1.7;
  Camera h = sim::ring_cameras(held).front();
  h.id = "held_out";
  cams.push_back(h);  // last: feeds nothing
  return cams;
}

// A frame of the simulated actor and the visual hull of its studio cameras' masks (the held-out
// camera, last, left out), its mesh with exact crossings: where every evaluation here starts.
struct HullFrame {
  explicit HullFrame(sim::SimulatedStudio s) : studio(std::move(s)) {}
  sim::SimulatedStudio studio;
  testing::Frame f;
  std::vector<ColourView> views;
  std::vector<hull::View> cut_views;
  hull::SegmentSet set;
  hull::Mesh hull_mesh;
};

HullFrame hull_frame(sim::Motion motion, int64_t frame, uint64_t seed) {
  sim::StudioOptions so;
  so.actor.motion = motion;
  so.actor.seed = seed;
  HullFrame h(sim::SimulatedStudio::create(rig(), so).value());
  h.f = testing::render_frame(h.studio, frame);
  h.views = h.f.views();
  h.views.pop_back();  // the held-out camera
  for (const auto& v : h.views) h.cut_views.push_back({v.camera, v.mask});
  h.set = hull::visual_hull(testing::studio_grid(kGrid), h.cut_views).value();
  h.hull_mesh = hull::segment_marching_cubes(h.set);
  EXPECT_TRUE(hull::refine_crossings(h.hull_mesh, h.set, h.cut_views).has_value());
  return h;
}

struct Case {
  testing::SurfaceScore hull, carved_score, refined;  // refined = carved + surface refinement
  double psnr_hull = 0, psnr_refined = 0;             // interior (2-px border excluded)
  double psnr_full_hull = 0, psnr_full_refined = 0;   // union of the silhouettes
  double psnr_carved = 0, psnr_full_carved = 0;
  double photo_target_error = 0, photo_stay_error = 0;  // metres (mean |target - truth|, |truth|)
  // The held-out view's error split (testing/texture_oracle.h), union PSNR: the refined mesh's
  // blend evaluated per sub-pixel (an atlas of unlimited resolution), and the same blend on the
  // TRUE surface with true visibility (no geometry error: what the texturing alone costs).
  testing::HeldOutScore per_pixel, oracle;
  std::size_t carved = 0;
};

const Case& evaluate(sim::Motion motion, int64_t frame) {
  static std::map<std::pair<int, int64_t>, Case> cache;
  const auto key = std::make_pair(int(motion), frame);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  HullFrame h = hull_frame(motion, frame, 1);
  sim::SimulatedStudio& studio = h.studio;
  const testing::Frame& f = h.f;
  const auto& views = h.views;
  const hull::SegmentSet& set = h.set;
  const hull::Mesh& hull_mesh = h.hull_mesh;
  CarveOptions o;
  o.threads = 2;
  const CarveResult carved = photo_carve(set, views, o).value();
  const hull::Mesh carved_mesh = refined_mesh(carved.set, set, views, 2).value();
  SurfaceRefineOptions so_;
  so_.cell = 3.0 / kGrid;
  so_.threads = 2;
  const auto sr = refine_surface(carved_mesh, views, so_).value();
  std::printf(
      "  surface refine: %d iterations, anchored %zu, evidence %zu, unseen %zu of %zu vertices, "
      "mean shift %.2f mm\n",
      sr.iterations, sr.anchored, sr.evidence, sr.unseen, sr.mesh.vertices.size(),
      1e3 * sr.mean_shift);
  const hull::Mesh& mesh = sr.mesh;
  Case c;
  {
    // The photo term's data (one iteration, no shape prior) against the true offset along each
    // vertex's search direction: how far its targets are from the truth, against not moving.
    SurfaceRefineOptions po = so_;
    po.iterations = 1, po.shape_steps = 0;
    const auto pr = refine_surface(carved_mesh, views, po).value();
    double e_t = 0, e_0 = 0, bias = 0, tb = 0;
    int cnt = 0, hist[5] = {0, 0, 0, 0, 0};
    for (std::size_t n = 0; n < carved_mesh.vertices.size(); ++n) {
      if (pr.first_weight.empty() || pr.first_weight[n] <= 0) continue;
      const Eigen::Vector3d dir = pr.directions[n].cast<double>();
      const Eigen::Vector3d o = carved_mesh.vertices[n].cast<double>() + 0.06 * dir;
      const auto hit = f.truth.body.ray_hit(o, -dir);
      if (!hit) continue;
      const double truth = 0.06 - hit->t;
      if (std::abs(truth) > 0.05) continue;
      const double t = pr.first_target[n];
      e_t += std::abs(t - truth), e_0 += std::abs(truth), bias += t - truth, tb += truth, ++cnt;
      hist[std::min(4, int(std::abs(t - truth) / (0.5 * 3.0 / kGrid)))]++;
    }
    c.photo_target_error = cnt ? e_t / cnt : 0, c.photo_stay_error = cnt ? e_0 / cnt : 0;
    std::printf(
        "  photo term (1 iteration) on %d vertices: |target - truth| %.2f mm, |truth| %.2f mm, "
        "bias %.2f mm, truth mean %.2f; err hist (half cells) %d %d %d %d %d\n",
        cnt, 1e3 * e_t / cnt, 1e3 * e_0 / cnt, 1e3 * bias / cnt, 1e3 * tb / cnt, hist[0], hist[1],
        hist[2], hist[3], hist[4]);
  }
  c.carved = carved.carved;
  c.hull = testing::surface_distance(hull_mesh, f.truth.body);
  c.carved_score = testing::surface_distance(carved_mesh, f.truth.body);
  c.refined = testing::surface_distance(mesh, f.truth.body);
  Mask truth_mask;
  studio.render(int(f.cameras.size()) - 1, frame, nullptr, &truth_mask);
  const Mask actor = testing::erode(truth_mask, 2);
  TextureOptions to;
  to.threads = 2;
  for (const hull::Mesh* m : std::vector<const hull::Mesh*>{&hull_mesh, &carved_mesh, &mesh}) {
    const auto colours = vertex_colours(*m, views, to).value();
    const Image<Rgb8> rendered = testing::render_coloured(*m, colours, f.cameras.back());
    {
      // Interior pixels whose centre no triangle covers (left black by the unfiltered render).
      std::size_t holes = 0;
      for (int y = 0; y < actor.height(); ++y)
        for (int x = 0; x < actor.width(); ++x) {
          const Rgb8 q = rendered.view().row(y)[x];
          holes += actor.view().row(y)[x] && q.r == 0 && q.g == 0 && q.b == 0;
        }
      std::printf("  interior px the unfiltered render leaves black: %zu\n", holes);
    }
    (m == &mesh          ? c.psnr_refined
     : m == &carved_mesh ? c.psnr_carved
                         : c.psnr_hull) = testing::psnr(rendered, f.images.back(), actor);
    Mask covered;
    const Image<Rgb8> over = testing::render_over(
        *m, colours, f.cameras.back(), studio.background(int(f.cameras.size()) - 1), 4, &covered);
    Mask both = truth_mask;
    for (int y = 0; y < both.height(); ++y)
      for (int x = 0; x < both.width(); ++x)
        both.view().row(y)[x] = std::max(both.view().row(y)[x], covered.view().row(y)[x]);
    (m == &mesh          ? c.psnr_full_refined
     : m == &carved_mesh ? c.psnr_full_carved
                         : c.psnr_full_hull) = testing::psnr(over, f.images.back(), both);
    {
      // Where the union's squared error is: the actor's interior (true mask without its 2-px
      // border), the border band, and pixels the render covers but the truth does not.
      double se[3] = {0, 0, 0};
      std::size_t px[3] = {0, 0, 0};
      for (int y = 0; y < both.height(); ++y)
        for (int x = 0; x < both.width(); ++x) {
          if (!both.view().row(y)[x]) continue;
          const int k = actor.view().row(y)[x] ? 0 : truth_mask.view().row(y)[x] ? 1 : 2;
          const Rgb8 a = over.view().row(y)[x], b = f.images.back().view().row(y)[x];
          se[k] += double(a.r - b.r) * (a.r - b.r) + double(a.g - b.g) * (a.g - b.g) +
                   double(a.b - b.b) * (a.b - b.b);
          ++px[k];
        }
      // Where the mesh falls short of the true silhouette: interior pixels (the true mask
      // without its 2-px border) that no sub-pixel of the render covers.
      std::size_t short_px = 0;
      for (int y = 0; y < both.height(); ++y)
        for (int x = 0; x < both.width(); ++x)
          short_px += actor.view().row(y)[x] && !covered.view().row(y)[x];
      const double total = se[0] + se[1] + se[2];
      std::printf(
          "  %s union: %zu px interior (%.0f %% of the squared error), %zu border (%.0f %%), "
          "%zu outside the true mask (%.0f %%); %zu interior px uncovered\n",
          m == &mesh          ? "refined"
          : m == &carved_mesh ? "carved"
                              : "hull",
          px[0], 100 * se[0] / total, px[1], 100 * se[1] / total, px[2], 100 * se[2] / total,
          short_px);
    }
  }
  {
    const Camera& held = f.cameras.back();
    const Image<Rgb8>& plate = studio.background(int(f.cameras.size()) - 1);
    constexpr int ss = 4;
    Mask cov;
    std::size_t unseen = 0;
    const auto blend = TextureBlend::create(mesh, views, to).value();
    c.per_pixel = testing::score_held_out(
        testing::blend_over(testing::mesh_surface(mesh, held, ss), held, ss, blend, plate, &cov),
        cov, f.images.back(), truth_mask);
    const auto oracle_blend =
        TextureBlend::create(testing::true_mesh(f.truth.body), views, to).value();
    c.oracle =
        testing::score_held_out(testing::blend_over(testing::truth_surface(f.truth.body, held, ss),
                                                    held, ss, oracle_blend, plate, &cov, &unseen),
                                cov, f.images.back(), truth_mask);
    for (const auto& [what, sc] : std::vector<std::pair<const char*, testing::HeldOutScore>>{
             {"refined, per sub-pixel", c.per_pixel}, {"TRUE surface (oracle)", c.oracle}})
      std::printf(
          "  %s blend: union %.2f dB, interior %.2f dB; squared error interior %.0f %%, border "
          "%.0f %%, outside the true mask %.0f %% (%zu px)\n",
          what, sc.union_db, sc.interior_db, 100 * sc.share_interior, 100 * sc.share_border,
          100 * sc.share_outside, sc.outside_px);
    std::printf("  oracle: %zu of the true surface's sub-pixels seen by no camera (filled)\n",
                unseen);
  }
  std::printf("%s frame %lld, %d^2 columns: carved %zu of %zu voxels in %d iterations\n",
              sim::motion_name(motion), (long long)frame, kGrid, carved.carved, carved.voxels,
              carved.iterations);
  const auto row = [](const char* what, const testing::SurfaceScore& s, double psnr, double full) {
    std::printf(
        "  %-8s surface distance mean / p95 (mm): both %.2f / %.2f, mesh->truth %.2f / %.2f, "
        "truth->mesh %.2f / %.2f; held-out PSNR %.2f dB (interior), %.2f dB (union)\n",
        what, 1e3 * s.both.mean, 1e3 * s.both.p95, 1e3 * s.accuracy.mean, 1e3 * s.accuracy.p95,
        1e3 * s.completeness.mean, 1e3 * s.completeness.p95, psnr, full);
  };
  row("hull", c.hull, c.psnr_hull, c.psnr_full_hull);
  row("carved", c.carved_score, c.psnr_carved, c.psnr_full_carved);
  row("refined", c.refined, c.psnr_refined, c.psnr_full_refined);
  // Where the error is: share of the pooled mean and of the samples beyond the p95, per body
  // region, within one cell of the truth (placement) or beyond (excess or missed volume).
  for (const auto& [what, m] : std::vector<std::pair<const char*, const hull::Mesh*>>{
           {"hull", &hull_mesh}, {"carved", &carved_mesh}, {"refined", &mesh}}) {
    std::printf("  %-8s error by region (share of mean / of p95 tail):", what);
    for (const auto& b : testing::error_breakdown(*m, f.truth.body, 3.0 / kGrid))
      std::printf(" %s%s %.0f/%.0f %%", b.region.c_str(), b.far ? ">cell" : "", 100 * b.share,
                  100 * b.p95_share);
    std::printf("\n");
  }
  return cache[key] = c;
}

const std::vector<std::pair<sim::Motion, int64_t>> kPoses = {
    {sim::Motion::idle, 10},    // standing, arms hanging close to the body
    {sim::Motion::crouch, 45},  // deepest crouch: thighs against the chest, arms forward
};

TEST(PhotoCarve, RefinedSurfaceIsCloserToTheTruthThanTheHull) {
  const double cell = 3.0 / kGrid;
  double hull_mean = 0, hull_p95 = 0, mean = 0, p95 = 0;
  for (const auto& [motion, frame] : kPoses) {
    const Case& c = evaluate(motion, frame);
    EXPECT_GT(c.carved, 0u);
    // Never worse than the hull by more than one cell.
    EXPECT_LE(c.carved_score.both.mean, c.hull.both.mean + cell);
    EXPECT_LE(c.carved_score.both.p95, c.hull.both.p95 + cell);
    EXPECT_LE(c.carved_score.accuracy.mean, c.hull.accuracy.mean + cell);
    // Better than the hull in this frame.
    EXPECT_LT(c.carved_score.both.mean, c.hull.both.mean);
    EXPECT_LT(c.carved_score.both.p95, c.hull.both.p95);
    hull_mean += c.hull.both.mean, hull_p95 += c.hull.both.p95;
    mean += c.carved_score.both.mean, p95 += c.carved_score.both.p95;
  }
  const double mean_gain = 1 - mean / hull_mean, p95_gain = 1 - p95 / hull_p95;
  std::printf("carving over the poses: mean %.1f %% lower, p95 %.1f %% lower than the hull\n",
              100 * mean_gain, 100 * p95_gain);
  // Measured 12 % / 19 % (docs/offline.md).
  EXPECT_GE(mean_gain, 0.10);
  EXPECT_GE(p95_gain, 0.15);
}

// The surface stage after carving (default options: the shape prior with rim anchors, no photo
// term): closer to the truth than the carved mesh and the hull, never worse than the hull in any
// frame by more than one cell.
TEST(SurfaceRefine, CloserToTheTruthThanCarvingAndTheHull) {
  const double cell = 3.0 / kGrid;
  double hull_mean = 0, hull_p95 = 0, carved_mean = 0, carved_p95 = 0, mean = 0, p95 = 0;
  for (const auto& [motion, frame] : kPoses) {
    const Case& c = evaluate(motion, frame);
    EXPECT_LE(c.refined.both.mean, c.hull.both.mean + cell);
    EXPECT_LE(c.refined.both.p95, c.hull.both.p95 + cell);
    EXPECT_LE(c.refined.accuracy.mean, c.hull.accuracy.mean + cell);
    EXPECT_LE(c.refined.completeness.mean, c.hull.completeness.mean + cell);
    EXPECT_LT(c.refined.both.mean, c.carved_score.both.mean) << sim::motion_name(motion);
    EXPECT_LT(c.refined.both.p95, c.carved_score.both.p95) << sim::motion_name(motion);
    hull_mean += c.hull.both.mean, hull_p95 += c.hull.both.p95;
    carved_mean += c.carved_score.both.mean, carved_p95 += c.carved_score.both.p95;
    mean += c.refined.both.mean, p95 += c.refined.both.p95;
  }
  const double mean_gain = 1 - mean / hull_mean, p95_gain = 1 - p95 / hull_p95;
  std::printf(
      "carved + surface over the poses: mean %.1f %% lower, p95 %.1f %% lower than the "
      "hull (carving alone %.1f %% / %.1f %%)\n",
      100 * mean_gain, 100 * p95_gain, 100 * (1 - carved_mean / hull_mean),
      100 * (1 - carved_p95 / hull_p95));
  // Measured 20.8 % / 26.1 % with the facet middles anchored (18.9 / 23.6 % with every facet
  // vertex anchored; docs/offline.md); the 30 % is not reached.
  EXPECT_GE(mean_gain, 0.19);
  EXPECT_GE(p95_gain, 0.24);
}

// Poses the surface stage's settings (steps, anchors, the hull constraint) were not chosen on:
// other actors (seeds 2 and 3: other proportions, clothing and phase) and other frames of the
// concave motions. Surface distances only (hull, carved, carved + surface stage).
struct ShapeCase {
  testing::SurfaceScore hull, carved, refined;
};

ShapeCase evaluate_shape(sim::Motion motion, int64_t frame, uint64_t seed) {
  const HullFrame h = hull_frame(motion, frame, seed);
  const testing::Frame& f = h.f;
  const auto& views = h.views;
  const hull::SegmentSet& set = h.set;
  const hull::Mesh& hull_mesh = h.hull_mesh;
  CarveOptions o;
  o.threads = 2;
  const hull::Mesh carved =
      refined_mesh(photo_carve(set, views, o).value().set, set, views, 2).value();
  SurfaceRefineOptions sro;
  sro.cell = 3.0 / kGrid;
  sro.threads = 2;
  const hull::Mesh refined = refine_surface(carved, views, sro).value().mesh;
  ShapeCase c;
  c.hull = testing::surface_distance(hull_mesh, f.truth.body);
  c.carved = testing::surface_distance(carved, f.truth.body);
  c.refined = testing::surface_distance(refined, f.truth.body);
  std::printf(
      "%s frame %lld actor seed %llu (validation): surface distance mean / p95 (mm) hull %.2f / "
      "%.2f, carved %.2f / %.2f, carved + surface %.2f / %.2f\n",
      sim::motion_name(motion), (long long)frame, (unsigned long long)seed, 1e3 * c.hull.both.mean,
      1e3 * c.hull.both.p95, 1e3 * c.carved.both.mean, 1e3 * c.carved.both.p95,
      1e3 * c.refined.both.mean, 1e3 * c.refined.both.p95);
  return c;
}

TEST(SurfaceRefine, ValidationPosesNotTunedOn) {
  const double cell = 3.0 / kGrid;
  double hull_mean = 0, hull_p95 = 0, mean = 0, p95 = 0;
  for (const auto& [motion, frame, seed] : std::vector<std::tuple<sim::Motion, int64_t, uint64_t>>{
           {sim::Motion::crouch, 50, 2},   // another actor, deepest crouch
           {sim::Motion::idle, 40, 3}}) {  // another actor standing, arms at the sides
    const ShapeCase c = evaluate_shape(motion, frame, seed);
    EXPECT_LE(c.refined.both.mean, c.hull.both.mean + cell);
    EXPECT_LE(c.refined.both.p95, c.hull.both.p95 + cell);
    EXPECT_LT(c.refined.both.mean, c.carved.both.mean) << sim::motion_name(motion);
    EXPECT_LT(c.refined.both.p95, c.carved.both.p95) << sim::motion_name(motion);
    hull_mean += c.hull.both.mean, hull_p95 += c.hull.both.p95;
    mean += c.refined.both.mean, p95 += c.refined.both.p95;
  }
  const double mean_gain = 1 - mean / hull_mean, p95_gain = 1 - p95 / hull_p95;
  std::printf(
      "validation poses: carved + surface mean %.1f %% lower, p95 %.1f %% lower than the hull\n",
      100 * mean_gain, 100 * p95_gain);
  // Measured 21.5 % / 25.6 % with the facet middles anchored (18.8 % / 22.5 % before;
  // docs/offline.md; the 30 % is not reached).
  EXPECT_GE(mean_gain, 0.19);
  EXPECT_GE(p95_gain, 0.23);
}

// A larger studio's rig (8 ring + overhead + 8 on a low ring 0.9 m high between the ring's
// azimuths: 17 cameras). More cameras judge each voxel, from wider angles whose spill and ring
// light tint differ; judged by all of them the carve ate into the true surface and the refined
// mesh (carve + surface stage, the --refine --surface 10 product) came out further from the truth
// than the hull. With the default judges (CarveOptions::max_judges, the most frontal 3) it is
// closer than the hull (measured -7.5 % / -18.7 % mean / p95; all judges +11.7 % / +5.8 %).
TEST(PhotoCarve, SeventeenCamerasJudgedByTheMostFrontalBeatTheHull) {
  sim::RingOptions ring;
  ring.count = 9;
  std::vector<Camera> cams = sim::ring_cameras(ring);
  sim::RingOptions low;
  low.count = 8;
  low.overhead = false;
  low.height_m = 0.9;
  low.look_at_y = 1.0;
  low.first_azimuth_deg = 22.5;
  for (Camera c : sim::ring_cameras(low)) {
    c.id = "low" + c.id.substr(3);
    cams.push_back(c);
  }
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::idle;
  so.cyclorama_height = 6;  // the low views see cloth above the actor, not the studio's roof
  auto studio = sim::SimulatedStudio::create(cams, so).value();
  const testing::Frame f = testing::render_frame(studio, 10);
  const auto views = f.views();
  ASSERT_EQ(views.size(), 17u);
  std::vector<hull::View> cut;
  for (const auto& v : views) cut.push_back({v.camera, v.mask});
  const hull::SegmentSet set = hull::visual_hull(testing::studio_grid(kGrid), cut).value();
  hull::Mesh hull_mesh = hull::segment_marching_cubes(set);
  ASSERT_TRUE(hull::refine_crossings(hull_mesh, set, cut));
  const auto hull_score = testing::surface_distance(hull_mesh, f.truth.body);
  auto refined = [&](int judges) {
    CarveOptions o;
    o.threads = 2;
    o.max_judges = judges;
    const auto carved = photo_carve(set, views, o).value();
    const hull::Mesh m = refined_mesh(carved.set, set, views, 2).value();
    SurfaceRefineOptions so_;
    so_.cell = 3.0 / kGrid;
    so_.threads = 2;
    return testing::surface_distance(refine_surface(m, views, so_).value().mesh, f.truth.body);
  };
  ASSERT_EQ(CarveOptions{}.max_judges, 3);
  const auto frontal = refined(CarveOptions{}.max_judges), all = refined(0);
  std::printf("17 cameras, idle f10: hull %.2f / %.2f mm, refined (3 judges) %.2f / %.2f, "
              "refined (all judges) %.2f / %.2f\n",
              1e3 * hull_score.both.mean, 1e3 * hull_score.both.p95, 1e3 * frontal.both.mean,
              1e3 * frontal.both.p95, 1e3 * all.both.mean, 1e3 * all.both.p95);
  EXPECT_LT(frontal.both.mean, 0.97 * hull_score.both.mean);
  EXPECT_LT(frontal.both.p95, 0.9 * hull_score.both.p95);
  // The control: judged by all, the same refinement is worse than the hull.
  EXPECT_GT(all.both.mean, hull_score.both.mean);
}

TEST(Texture, HeldOutViewPsnr) {
  for (const auto& [motion, frame] : kPoses) {
    const Case& c = evaluate(motion, frame);
    // The carved mesh: >= 28 dB over the interior (28.3 / 28.7 measured).
    EXPECT_GE(c.psnr_carved, 28.0) << sim::motion_name(motion);
    EXPECT_GE(c.psnr_carved, c.psnr_hull - 0.25) << sim::motion_name(motion);
    // Over the union of the true and the rendered silhouettes (anti-aliased render over the
    // held-out camera's clean plate): carved 24.2 (idle) and 22.9 dB (crouch); the surface stage
    // shrinks the hull's bulges outside the true silhouette: 25.4 / 23.8 dB. The 28 dB is
    // not reached there (docs/offline.md).
    EXPECT_GE(c.psnr_full_carved, 22.0) << sim::motion_name(motion);
    EXPECT_GE(c.psnr_full_carved, c.psnr_full_hull - 0.25) << sim::motion_name(motion);
    EXPECT_GE(c.psnr_full_refined, c.psnr_full_carved + 0.5) << sim::motion_name(motion);
    EXPECT_GE(c.psnr_refined, 27.5) << sim::motion_name(motion);
    // Geometry against texturing (the oracle): the same blend on the TRUE surface, with true
    // visibility, reaches the 28 dB over the union of silhouettes (measured 31.2 / 30.5
    // dB); on the refined mesh it stays ~6 dB lower (25.6 / 24.2 dB) whether the colour is per
    // vertex or per sub-pixel (an atlas would not close it: within 0.3 dB). What limits the
    // held-out view is the shape: half of the union's squared error is mesh outside the true
    // silhouette. (In this test, not its own: each ctest process re-evaluates the poses.)
    EXPECT_GE(c.oracle.union_db, 29.5) << sim::motion_name(motion);
    EXPECT_GE(c.oracle.interior_db, 32.0) << sim::motion_name(motion);
    // Per-vertex colour is within half a dB of the blend evaluated at every rendered point.
    EXPECT_GE(c.psnr_full_refined, c.per_pixel.union_db - 0.5) << sim::motion_name(motion);
    EXPECT_LT(c.psnr_full_refined, c.oracle.union_db) << sim::motion_name(motion);
  }
}

// Incremental judging (re-judging only the surface voxels whose normal or consulted depth pixels
// changed) carves exactly the voxels judging every surface voxel every iteration carves: on the
// 9-camera crouch, on a patterned costume with a looser threshold (more carving, more
// iterations), and with a distorted camera (its pixels through the full projection); and it
// judges fewer voxels (the control that it skipped any).
TEST(PhotoCarve, IncrementalJudgingCarvesTheSameVoxels) {
  struct Case {
    const char* name;
    int cameras, width, height, grid;
    double focal, threshold;
    bool patterned, distorted;
    sim::Motion motion;
    int64_t frame;
  };
  for (const Case& k :
       {Case{"crouch, 9 cameras", 9, 704, 576, 160, 560, 6, false, false, sim::Motion::crouch, 45},
        Case{"patterned, threshold 4", 8, 352, 288, 128, 280, 4, true, false, sim::Motion::idle,
             10},
        Case{"distorted camera", 6, 352, 288, 96, 280, 5, false, true, sim::Motion::crouch, 30}}) {
    SCOPED_TRACE(k.name);
    sim::RingOptions ring;
    ring.count = k.cameras;
    ring.width = k.width, ring.height = k.height, ring.focal_px = k.focal;
    std::vector<Camera> cameras = sim::ring_cameras(ring);
    if (k.distorted) cameras[1].distortion = Distortion::opencv(-0.05, 0.01, 0, 0, 0);
    sim::StudioOptions so;
    so.actor.motion = k.motion;
    so.patterned_costume = k.patterned;
    auto studio = sim::SimulatedStudio::create(cameras, so).value();
    const testing::Frame f = testing::render_frame(studio, k.frame);
    const auto views = f.views();
    std::vector<hull::View> cut_views;
    for (const auto& v : views) cut_views.push_back({v.camera, v.mask});
    const hull::SegmentSet set = hull::visual_hull(testing::studio_grid(k.grid), cut_views).value();
    CarveOptions every, incremental;
    every.threshold = incremental.threshold = k.threshold;
    every.incremental = false;
    const auto a = photo_carve(set, views, every).value();
    const auto b = photo_carve(set, views, incremental).value();
    std::printf("%s: %zu carved in %d iterations; judged %zu (every voxel) vs %zu (incremental)\n",
                k.name, a.carved, a.iterations, a.judged, b.judged);
    testing::expect_same_carve(a, b);
  }
}

TEST(PhotoCarve, IndependentOfThreadsAndRefusesBadInput) {
  sim::RingOptions ring;
  ring.count = 6;
  ring.width = 352, ring.height = 288, ring.focal_px = 280;
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::idle;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(ring), so).value();
  const testing::Frame f = testing::render_frame(studio, 5);
  const auto views = f.views();
  std::vector<hull::View> cut_views;
  for (const auto& v : views) cut_views.push_back({v.camera, v.mask});
  const hull::SegmentSet set = hull::visual_hull(testing::studio_grid(96), cut_views).value();
  CarveOptions one, two;
  two.threads = 2;
  const auto a = photo_carve(set, views, one).value();
  const auto b = photo_carve(set, views, two).value();
  EXPECT_GT(a.carved, 0u);
  EXPECT_EQ(a.set, b.set);
  EXPECT_LE(a.set.volume(), set.volume());
  // Two judges (fewer than the cameras that see many voxels here): also thread-independent.
  one.max_judges = two.max_judges = 2;
  EXPECT_EQ(photo_carve(set, views, one).value().set, photo_carve(set, views, two).value().set);
  // Bad options and a mask of the wrong size: one line each, nothing carved.
  CarveOptions bad;
  bad.threshold = -1;
  ASSERT_FALSE(photo_carve(set, views, bad));
  EXPECT_NE(photo_carve(set, views, bad).error().message.find("threshold"), std::string::npos);
  CarveOptions one_judge;
  one_judge.max_judges = 1;  // fewer judges than min_cameras: nothing could be compared
  ASSERT_FALSE(photo_carve(set, views, one_judge));
  EXPECT_NE(photo_carve(set, views, one_judge).error().message.find("max_judges"),
            std::string::npos);
  auto wrong = views;
  const RunMask small(10, 10);
  wrong[2].mask = &small;
  ASSERT_FALSE(photo_carve(set, wrong, one));
  EXPECT_NE(photo_carve(set, wrong, one).error().message.find("cam2"), std::string::npos);
  ASSERT_FALSE(vertex_colours(hull::segment_marching_cubes(set), wrong));
  // The surface stage: both terms on, the same result on 1 and 2 threads; bad input refused.
  hull::Mesh m = hull::segment_marching_cubes(set);
  SurfaceRefineOptions s1;
  s1.cell = 3.0 / 96, s1.iterations = 2;
  SurfaceRefineOptions s2 = s1;
  s2.threads = 2;
  const auto r1 = refine_surface(m, views, s1).value();
  const auto r2 = refine_surface(m, views, s2).value();
  EXPECT_GT(r1.mean_shift, 0);
  EXPECT_GT(r1.anchored, 0u);
  EXPECT_EQ(r1.mesh.vertices, r2.mesh.vertices);
  EXPECT_EQ(r1.mesh.triangles, m.triangles);
  // The shape prior keeps every vertex inside each silhouette that contained it (the visual
  // hull contains the true surface); without the constraint, Laplacian steps move creases out.
  const auto left_silhouettes = [&](const hull::Mesh& before, const hull::Mesh& after) {
    int left = 0;
    for (std::size_t n = 0; n < before.vertices.size(); ++n)
      for (const auto& v : views) {
        const auto in = [&](const Eigen::Vector3f& x) {
          Eigen::Vector2d p;
          return v.camera->project(x.cast<double>(), &p) &&
                 v.mask->contains(int(std::lround(p.x())), int(std::lround(p.y())));
        };
        left += in(before.vertices[n]) && !in(after.vertices[n]);
      }
    return left;
  };
  SurfaceRefineOptions shape;
  shape.cell = 3.0 / 96;
  EXPECT_EQ(left_silhouettes(m, refine_surface(m, views, shape).value().mesh), 0);
  shape.inside_hull = false;
  EXPECT_GT(left_silhouettes(m, refine_surface(m, views, shape).value().mesh), 0);
  SurfaceRefineOptions s_bad = s1;
  s_bad.cell = 0;
  ASSERT_FALSE(refine_surface(m, views, s_bad));
  EXPECT_NE(refine_surface(m, views, s_bad).error().message.find("cell"), std::string::npos);
  ASSERT_FALSE(refine_surface(m, wrong, s1));
  EXPECT_FALSE(refine_surface(m, {}, s1));
  EXPECT_FALSE(photo_carve(set, {}, one));
}

}  // namespace
}  // namespace studio::offline

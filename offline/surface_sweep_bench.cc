// Development sweep (not a test): surface-stage variants on simulated poses, scored against the
// truth. Usage: offline_surface_sweep "variant;variant;..." where a variant is key=value,...
// (steps, lambda, rim, band, anchor, hull, order, fromhull, photo = photo-term iterations).
// Environment: GRID (columns, 256), POSES (indices into the list below, e.g. 34),
// COSTUME=patterned (the actor in sim's patterned costume instead of plain clothing),
// LOW_RING=N (N more cameras on a second ring 0.9 m high looking at 1.0 m, between the main
// ring's azimuths, the cyclorama's walls 6 m high instead of 4 so that they see cloth above the
// actor: a larger studio's rig, e.g. 8 + overhead + 8 = 17 cameras), LOSS_PER_CAMERA=1 (the
// hull's and the carved mesh's silhouette loss per camera: a mask wider than the actor shows),
// CARVE_MAX_JUDGES / CARVE_MIN_COS / CARVE_THRESHOLD (the carve's CarveOptions, default otherwise),
// RESPONSE=E,B[,SEED] (the cameras' colour responses differ: sim::random_camera_response with
// exposure spread E and white-balance spread B), BALANCE=0 (no colour balance before the carve),
// BALANCE_COS_DIFF / BALANCE_TOL (ColourBalanceOptions::max_cos_difference / tolerance).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/colour_balance.h"
#include "offline/photo_carve.h"
#include "offline/surface_refine.h"
#include "offline/view_sampling.h"
#include "sim/cameras.h"
#include "testing/truth.h"

using namespace studio;
using namespace studio::offline;

struct Pose {
  sim::Motion motion;
  int64_t frame;
  uint64_t seed;
  bool train;
};

struct Prepared {
  testing::Frame f;
  std::vector<ColourView> views;
  std::vector<Image<Rgb8>> balanced;  // the images after the colour balance (BALANCE)
  hull::Mesh hull_mesh, carved_mesh;
  testing::SurfaceScore hull, carved;
};

// Share of the mask pixels (eroded by 1 px) the mesh's projection does not cover.
double silhouette_loss(const hull::Mesh& m, const std::vector<ColourView>& views) {
  auto sv = prepare_views(views, 1).value();
  double lost = 0, total = 0;
  for (std::size_t c = 0; c < sv.size(); ++c) {
    DepthBuffer d;
    d.reset(sv[c]);
    d.mesh(sv[c], m);
    for (int y = 0; y < sv[c].camera->height; ++y)
      for (int x = 0; x < sv[c].camera->width; ++x)
        if (sv[c].inside(x, y)) {
          ++total;
          lost += !std::isfinite(d.at(x, y));
        }
  }
  return lost / total;
}

int main(int argc, char** argv) {
  const int grid = std::getenv("GRID") ? std::atoi(std::getenv("GRID")) : 256;
  std::vector<Pose> poses = {
      {sim::Motion::idle, 10, 1, true},      {sim::Motion::crouch, 45, 1, true},
      {sim::Motion::crouch, 25, 1, false},   {sim::Motion::crouch, 50, 2, false},
      {sim::Motion::idle, 40, 3, false},     {sim::Motion::walk, 20, 1, false},
      {sim::Motion::arm_swing, 30, 2, false}};
  if (std::getenv("POSES")) {
    std::vector<Pose> sel;
    for (char ch : std::string(std::getenv("POSES"))) sel.push_back(poses[ch - '0']);
    poses = sel;
  }
  std::vector<Prepared> prep(poses.size());
  sim::RingOptions ring;
  ring.count = 9;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sim::StudioOptions so;
    so.actor.motion = poses[i].motion;
    so.actor.seed = poses[i].seed;
    so.patterned_costume =
        std::getenv("COSTUME") && std::string(std::getenv("COSTUME")) == "patterned";
    std::vector<Camera> cams = sim::ring_cameras(ring);
    if (const char* low = std::getenv("LOW_RING")) {
      so.cyclorama_height = 6;  // a level view from 0.9 m sees above the 4 m walls
      sim::RingOptions lo;
      lo.count = std::atoi(low);
      lo.overhead = false;
      lo.height_m = 0.9;
      lo.look_at_y = 1.0;
      lo.first_azimuth_deg = 180.0 / lo.count;
      for (Camera c : sim::ring_cameras(lo)) {
        c.id = "low" + c.id.substr(3);
        cams.push_back(c);
      }
    }
    // RESPONSE=E,B[,SEED]: the cameras' colour responses differ (sim::random_camera_response:
    // exposure spread E, white-balance spread B); BALANCE=0: no colour balance before the carve.
    if (const char* r = std::getenv("RESPONSE")) {
      double e = 0, b = 0;
      unsigned long long seed = 1;
      std::sscanf(r, "%lf,%lf,%llu", &e, &b, &seed);
      so.camera_response = sim::random_camera_response(int(cams.size()), seed, e, b);
    }
    const bool balance = !std::getenv("BALANCE") || std::atoi(std::getenv("BALANCE")) != 0;
    auto studio = sim::SimulatedStudio::create(cams, so).value();
    Prepared& p = prep[i];
    p.f = testing::render_frame(studio, poses[i].frame);
    p.views = p.f.views();
    std::vector<hull::View> cut;
    for (const auto& v : p.views) cut.push_back({v.camera, v.mask});
    const auto set = hull::visual_hull(testing::studio_grid(grid), cut).value();
    p.hull_mesh = hull::segment_marching_cubes(set);
    (void)hull::refine_crossings(p.hull_mesh, set, cut);
    if (balance) {
      ColourBalanceOptions bo;
      bo.threads = 2;
      if (const char* d = std::getenv("BALANCE_COS_DIFF")) bo.max_cos_difference = std::atof(d);
      if (const char* t = std::getenv("BALANCE_TOL")) bo.tolerance = std::atof(t);
      const auto t0 = std::chrono::steady_clock::now();
      hull::CutOptions cut_options;
      cut_options.threads = 2;
      const ColourBalance cb =
          estimate_colour_balance(testing::studio_grid(grid), p.views, cut_options, 128, bo)
              .value();
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      p.views = apply_colour_balance(p.views, cb, &p.balanced);
      // Against the truth: the display-space gains (g^(1/2.2)) that equalise the cameras,
      // geometric mean 1 per channel; the worst camera and channel.
      double worst = 0;
      const auto want = sim::balancing_gains(so.camera_response);
      for (std::size_t c = 0; c < want.size(); ++c)
        for (int k = 0; k < 3; ++k)
          worst = std::max(worst, std::abs(cb.estimated[c][k] / want[c][std::size_t(k)] - 1));
      float largest = 0;
      for (const auto& g : cb.estimated)
        largest = std::max(largest, (g.array() - 1).abs().maxCoeff());
      std::printf(
          "  balance (%s): %zu points, %d pairs, residual %.4f, largest |gain - 1| %.2f %%, worst "
          "gain error %.2f %% (%.0f ms)\n",
          cb.applied ? "applied" : "within the tolerance", cb.points, cb.pairs, cb.residual,
          100 * largest, 100 * worst, ms);
    }
    CarveOptions co;
    co.threads = 2;
    if (const char* j = std::getenv("CARVE_MAX_JUDGES")) co.max_judges = std::atoi(j);
    if (const char* c = std::getenv("CARVE_MIN_COS")) co.min_cos = std::atof(c);
    if (const char* t = std::getenv("CARVE_THRESHOLD")) co.threshold = std::atof(t);
    const auto carved = photo_carve(set, p.views, co).value();
    p.carved_mesh = refined_mesh(carved.set, set, p.views, 2).value();
    p.hull = testing::surface_distance(p.hull_mesh, p.f.truth.body);
    p.carved = testing::surface_distance(p.carved_mesh, p.f.truth.body);
    if (std::getenv("LOSS_PER_CAMERA")) {  // the hull's and the carved mesh's loss per camera
      for (std::size_t c = 0; c < p.views.size(); ++c) {
        const std::vector<ColourView> one = {p.views[c]};
        std::printf("  %s: hull loss %.4f carved loss %.4f\n", p.views[c].camera->id.c_str(),
                    silhouette_loss(p.hull_mesh, one), silhouette_loss(p.carved_mesh, one));
      }
    }
    std::printf("pose %s f%lld seed %llu %s: hull %.2f / %.2f, carved %.2f / %.2f (loss %.4f)\n",
                sim::motion_name(poses[i].motion), (long long)poses[i].frame,
                (unsigned long long)poses[i].seed, poses[i].train ? "train" : "valid",
                1e3 * p.hull.both.mean, 1e3 * p.hull.both.p95, 1e3 * p.carved.both.mean,
                1e3 * p.carved.both.p95, silhouette_loss(p.carved_mesh, p.views));
    std::fflush(stdout);
  }
  std::stringstream all(argc > 1 ? argv[1] : "");
  std::string variant;
  while (std::getline(all, variant, ';')) {
    SurfaceRefineOptions o;
    o.cell = 3.0 / grid;
    o.threads = 2;
    bool from_hull = false;
    std::stringstream kv(variant);
    std::string item;
    while (std::getline(kv, item, ',')) {
      const auto eq = item.find('=');
      const std::string k = item.substr(0, eq);
      const double v = std::atof(item.substr(eq + 1).c_str());
      if (k == "steps")
        o.shape_steps = int(v);
      else if (k == "lambda")
        o.shape_lambda = v;
      else if (k == "rim")
        o.rim_cos = v;
      else if (k == "band")
        o.rim_band_cells = v;
      else if (k == "anchor")
        o.anchor_rims = v != 0;
      else if (k == "hull")
        o.inside_hull = v != 0;
      else if (k == "order")
        o.shape_order = int(v);
      else if (k == "fromhull")
        from_hull = v != 0;
      else if (k == "photo")
        o.iterations = int(v);
      else {
        std::fprintf(stderr, "unknown key %s\n", k.c_str());
        return 1;
      }
    }
    double hm[2] = {0, 0}, hp[2] = {0, 0}, m[2] = {0, 0}, q[2] = {0, 0};
    std::printf("variant %s\n", variant.c_str());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const Prepared& p = prep[i];
      const auto r = refine_surface(from_hull ? p.hull_mesh : p.carved_mesh, p.views, o).value();
      const auto s = testing::surface_distance(r.mesh, p.f.truth.body);
      const int k = poses[i].train ? 0 : 1;
      hm[k] += p.hull.both.mean, hp[k] += p.hull.both.p95, m[k] += s.both.mean, q[k] += s.both.p95;
      std::printf(
          "  %-9s f%-3lld s%llu: %.2f / %.2f (%+.1f %% / %+.1f %%) acc %.2f compl %.2f anchored "
          "%zu/%zu loss %.4f\n",
          sim::motion_name(poses[i].motion), (long long)poses[i].frame,
          (unsigned long long)poses[i].seed, 1e3 * s.both.mean, 1e3 * s.both.p95,
          100 * (s.both.mean / p.hull.both.mean - 1), 100 * (s.both.p95 / p.hull.both.p95 - 1),
          1e3 * s.accuracy.mean, 1e3 * s.completeness.mean, r.anchored, r.mesh.vertices.size(),
          silhouette_loss(r.mesh, p.views));
      std::fflush(stdout);
    }
    for (int k = 0; k < 2; ++k)
      if (hm[k] > 0)
        std::printf("  %s: mean %+.1f %%, p95 %+.1f %%\n", k ? "valid" : "train",
                    100 * (m[k] / hm[k] - 1), 100 * (q[k] / hp[k] - 1));
  }
}

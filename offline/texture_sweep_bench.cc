// Development sweep (not a test): texture-blend variants against a held-out camera's true image,
// with the error split into geometry and texturing (testing/texture_oracle.h). Per pose and
// variant: the product (per-vertex colour on the hull, the carved and the surface-refined mesh),
// the same blend per sub-pixel on the refined mesh, and on the TRUE surface (the oracle).
// Usage: offline_texture_sweep "variant;variant;..." where a variant is key=value,... (keys:
// min_cos, margin, slack, sharp); POSES=0123456 selects poses (0, 1: refine_test's pair);
// RESPONSE=E,B[,SEED]: the rig's cameras differ in colour response (sim::random_camera_response;
// the held-out camera keeps 1, 1, 1); BALANCE=0: no colour balance (offline/colour_balance.h).
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
#include "offline/texture.h"
#include "sim/cameras.h"
#include "testing/texture_oracle.h"
#include "testing/truth.h"

using namespace studio;
using namespace studio::offline;

namespace {

struct Pose {
  sim::Motion motion;
  int64_t frame;
  uint64_t seed;
};

// refine_test's rig: 8 ring cameras + overhead, and a held-out camera between two ring cameras.
std::vector<Camera> rig() {
  sim::RingOptions ring;
  ring.count = 9;
  std::vector<Camera> cams = sim::ring_cameras(ring);
  sim::RingOptions held = ring;
  held.count = 8;
  held.overhead = false;
  held.first_azimuth_deg = 22.5;
  held.height_m = 1.7;
  Camera h = sim::ring_cameras(held).front();
  h.id = "held_out";
  cams.push_back(h);
  return cams;
}

struct Prepared {
  testing::Frame f;
  std::vector<ColourView> views;
  std::vector<Image<Rgb8>> balanced;  // the images after the colour balance
  hull::Mesh hull_mesh, carved_mesh, refined_mesh, truth_mesh;
  Image<Rgb8> plate;
  Mask true_mask;
  std::vector<testing::SurfaceSample> truth_px, refined_px;
};

}  // namespace

int main(int argc, char** argv) {
  const int grid = std::getenv("GRID") ? std::atoi(std::getenv("GRID")) : 256;
  const int ss = 4;
  std::vector<Pose> poses = {{sim::Motion::idle, 10, 1},     {sim::Motion::crouch, 45, 1},
                             {sim::Motion::crouch, 25, 1},   {sim::Motion::crouch, 50, 2},
                             {sim::Motion::idle, 40, 3},     {sim::Motion::walk, 20, 1},
                             {sim::Motion::arm_swing, 30, 2}};
  if (std::getenv("POSES")) {
    std::vector<Pose> sel;
    for (char ch : std::string(std::getenv("POSES"))) sel.push_back(poses[ch - '0']);
    poses = sel;
  }
  std::vector<Prepared> prep(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sim::StudioOptions so;
    so.actor.motion = poses[i].motion;
    so.actor.seed = poses[i].seed;
    if (const char* r = std::getenv("RESPONSE")) {  // the held-out camera (last) keeps 1, 1, 1
      double e = 0, b = 0;
      unsigned long long seed = 1;
      std::sscanf(r, "%lf,%lf,%llu", &e, &b, &seed);
      so.camera_response = sim::random_camera_response(int(rig().size()), seed, e, b);
      so.camera_response.back() = {1, 1, 1};
    }
    auto studio = sim::SimulatedStudio::create(rig(), so).value();
    Prepared& p = prep[i];
    p.f = testing::render_frame(studio, poses[i].frame);
    p.views = p.f.views();
    p.views.pop_back();
    if (!std::getenv("BALANCE") || std::atoi(std::getenv("BALANCE")) != 0) {
      const ColourBalance cb = estimate_colour_balance(testing::studio_grid(grid), p.views).value();
      p.views = apply_colour_balance(p.views, cb, &p.balanced);
      std::printf("  balance %s\n", cb.applied ? "applied" : "within the tolerance");
    }
    const int held = int(p.f.cameras.size()) - 1;
    studio.render(held, poses[i].frame, nullptr, &p.true_mask);
    p.plate = studio.background(held);
    std::vector<hull::View> cut;
    for (const auto& v : p.views) cut.push_back({v.camera, v.mask});
    const auto set = hull::visual_hull(testing::studio_grid(grid), cut).value();
    p.hull_mesh = hull::segment_marching_cubes(set);
    (void)hull::refine_crossings(p.hull_mesh, set, cut);
    CarveOptions co;
    co.threads = 2;
    const auto carved = photo_carve(set, p.views, co).value();
    p.carved_mesh = refined_mesh(carved.set, set, p.views, 2).value();
    SurfaceRefineOptions sro;
    sro.cell = 3.0 / grid;
    sro.threads = 2;
    p.refined_mesh = refine_surface(p.carved_mesh, p.views, sro).value().mesh;
    p.truth_mesh = testing::true_mesh(p.f.truth.body);
    p.truth_px = testing::truth_surface(p.f.truth.body, p.f.cameras.back(), ss);
    p.refined_px = testing::mesh_surface(p.refined_mesh, p.f.cameras.back(), ss);
    std::printf("pose %s f%lld seed %llu prepared\n", sim::motion_name(poses[i].motion),
                (long long)poses[i].frame, (unsigned long long)poses[i].seed);
    std::fflush(stdout);
  }
  std::stringstream all(argc > 1 ? argv[1] : "");
  std::string variant;
  while (std::getline(all, variant, ';')) {
    TextureOptions o;
    o.threads = 2;
    SurfaceRefineOptions sro;
    sro.cell = 3.0 / grid;
    sro.threads = 2;
    bool surface_variant = false;
    std::stringstream kv(variant);
    std::string item;
    while (std::getline(kv, item, ',')) {
      const auto eq = item.find('=');
      if (eq == std::string::npos) continue;
      const std::string k = item.substr(0, eq);
      const double v = std::atof(item.substr(eq + 1).c_str());
      if (k == "min_cos")
        o.min_cos = v;
      else if (k == "margin")
        o.edge_margin_px = int(v);
      else if (k == "slack")
        o.depth_tolerance = v;
      else if (k == "sharp")
        o.sharpness = v;
      else if (k == "steps")
        sro.shape_steps = int(v), surface_variant = true;
      else if (k == "band")
        sro.rim_band_cells = v, surface_variant = true;
      else if (k == "rim")
        sro.rim_cos = v, surface_variant = true;
      else if (k == "order")
        sro.shape_order = int(v), surface_variant = true;
      else if (k == "lambda")
        sro.shape_lambda = v, surface_variant = true;
      else if (k == "anchor")
        sro.anchor_rims = v != 0, surface_variant = true;
      else {
        std::fprintf(stderr, "unknown key %s\n", k.c_str());
        return 1;
      }
    }
    std::printf("variant %s\n", variant.c_str());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      Prepared& p = prep[i];
      if (surface_variant) {
        p.refined_mesh = refine_surface(p.carved_mesh, p.views, sro).value().mesh;
        p.refined_px = testing::mesh_surface(p.refined_mesh, p.f.cameras.back(), ss);
      }
      {
        const auto h = testing::surface_distance(p.hull_mesh, p.f.truth.body);
        const auto r = testing::surface_distance(p.refined_mesh, p.f.truth.body);
        std::printf(
            "  %-9s f%-3lld s%llu surface mean / p95 hull %.2f / %.2f refined %.2f / %.2f (%+.1f "
            "%% / %+.1f %%)\n",
            sim::motion_name(poses[i].motion), (long long)poses[i].frame,
            (unsigned long long)poses[i].seed, 1e3 * h.both.mean, 1e3 * h.both.p95,
            1e3 * r.both.mean, 1e3 * r.both.p95, 100 * (r.both.mean / h.both.mean - 1),
            100 * (r.both.p95 / h.both.p95 - 1));
      }
      const Camera& cam = p.f.cameras.back();
      const Image<Rgb8>& truth = p.f.images.back();
      const auto line = [&](const char* what, const testing::HeldOutScore& s, std::size_t unseen) {
        std::printf(
            "  %-9s f%-3lld s%llu %-22s union %.2f dB interior %.2f dB | SE interior %2.0f %% "
            "border %2.0f %% outside %2.0f %% (%zu px out, %zu uncovered, %zu unseen)\n",
            sim::motion_name(poses[i].motion), (long long)poses[i].frame,
            (unsigned long long)poses[i].seed, what, s.union_db, s.interior_db,
            100 * s.share_interior, 100 * s.share_border, 100 * s.share_outside, s.outside_px,
            s.uncovered_px, unseen);
      };
      for (const auto& [what, m] : std::vector<std::pair<const char*, const hull::Mesh*>>{
               {"hull/vertex", &p.hull_mesh},
               {"carved/vertex", &p.carved_mesh},
               {"refined/vertex", &p.refined_mesh}}) {
        const auto colours = vertex_colours(*m, p.views, o).value();
        Mask cov;
        const Image<Rgb8> r = testing::render_over(*m, colours, cam, p.plate, ss, &cov);
        line(what, testing::score_held_out(r, cov, truth, p.true_mask), 0);
      }
      {
        const auto blend = TextureBlend::create(p.refined_mesh, p.views, o).value();
        Mask cov;
        std::size_t unseen = 0;
        const Image<Rgb8> r =
            testing::blend_over(p.refined_px, cam, ss, blend, p.plate, &cov, &unseen);
        line("refined/pixel", testing::score_held_out(r, cov, truth, p.true_mask), unseen);
      }
      {
        const auto blend = TextureBlend::create(p.truth_mesh, p.views, o).value();
        Mask cov;
        std::size_t unseen = 0;
        const Image<Rgb8> r =
            testing::blend_over(p.truth_px, cam, ss, blend, p.plate, &cov, &unseen);
        line("TRUTH/pixel", testing::score_held_out(r, cov, truth, p.true_mask), unseen);
      }
      std::fflush(stdout);
    }
  }
}

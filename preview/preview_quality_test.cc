// The textured actor against a held-out camera, in process and deterministic (issue 16 "quality
// against truth"): the simulated studio (8 ring cameras + overhead, 352x288) renders each frame;
// the visual hull of their true masks (hull/ library, the node's grid 96 with exact crossings) or
// the actor's true surface is textured by ActorTexturer (gl/) from the held-out camera's pose,
// nearest camera and blend; the held-out camera (between cam0 and cam1, 1.8 m high) feeds
// nothing. PSNR over the union of the true silhouette (the simulator's mask) and the rendered
// one (fragments drawn), pooled over the frames.
//
// What it shows: with the true geometry the texturing reaches 27.5 dB (the issue asks 28), the
// blend far above nearest; with the visual hull of these cameras the silhouette is wrong by about a
// pixel all round (the hull of cameras 45 degrees apart exceeds a round limb by up to
// r (1 / cos 22.5 deg - 1) ~ 8 % of its radius between cameras; its flat facets cut inside it
// elsewhere), and every pixel there costs the difference between the actor and the blue
// backing: the figure is bounded by the geometry, not by the texturing (BENCHMARKS.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "actor_texturer.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "preview/camera_select.h"
#include "scene/view.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "support/cameras.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

namespace studio::preview {
namespace {

constexpr int kW = 352, kH = 288;

struct Score {
  double squared = 0;
  uint64_t samples = 0, both = 0, rendered_only = 0, true_only = 0;
  double squared_edge = 0;  // of the pixels in only one silhouette
  double psnr() const { return 10 * std::log10(255.0 * 255.0 / (squared / double(samples))); }
  double edge_share() const { return squared_edge / squared; }
};

struct Studio {
  std::vector<Camera> cameras;
  Camera held;
  Eigen::Vector3d eye, target{0, 1.1, 0};
  double fov_deg = 0;
};

Studio make_studio() {
  sim::RingOptions r;
  r.count = 9;
  r.width = kW;
  r.height = kH;
  r.focal_px *= double(kW) / 704.0;
  Studio s;
  s.cameras = sim::ring_cameras(r);
  const double az = 20 * std::numbers::pi / 180;
  s.eye = {3.6 * std::sin(az), 1.8, 3.6 * std::cos(az)};
  const double focal = 560.0 * kW / 704.0;
  s.held =
      support::look_at_camera("held", s.eye, s.target, Eigen::Vector3d::UnitY(), kW, kH, focal);
  s.fov_deg = 2 * std::atan(0.5 * kH / focal) * 180 / std::numbers::pi;
  return s;
}

scene::ActorMesh hull_mesh(const std::vector<Camera>& cameras, const std::vector<Mask>& masks) {
  std::vector<RunMask> runs;
  for (const Mask& m : masks) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<hull::View> views;
  for (std::size_t c = 0; c < cameras.size(); ++c) views.push_back({&cameras[c], &runs[c]});
  hull::GridSpec g;  // the preview studio test's hull.yaml
  g.box_min = {-1.5, 0.0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.cells_u = g.cells_v = 96;
  auto set = hull::visual_hull(g, views);
  EXPECT_TRUE(set.has_value());
  scene::ActorMesh out;
  if (!set) return out;
  const auto actors = hull::connected_components(*set, 0.01);
  EXPECT_FALSE(actors.empty());
  if (actors.empty()) return out;
  hull::Mesh mesh = hull::segment_marching_cubes(actors[0]);
  EXPECT_TRUE(hull::refine_crossings(mesh, actors[0], views).has_value());
  out.actor_id = "actor0";
  out.vertices = mesh.vertices;
  out.triangles = mesh.triangles;
  out.compute_normals();
  return out;
}

scene::ActorMesh true_mesh(const sim::ActorBody& body) {
  const sim::TriangleMesh m = body.mesh(64);
  scene::ActorMesh out;
  out.actor_id = "actor0";
  out.vertices = m.vertices;
  out.triangles = m.triangles;
  out.compute_normals();
  return out;
}

class PreviewQualityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto c = scene_render::HeadlessContext::create();
    ASSERT_TRUE(c.has_value()) << c.error().message;
    context_ = new scene_render::HeadlessContext(std::move(*c));
  }
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
  }

  // Scores nearest and blend for `frames`, with the hull (`hull` true) or the true surface.
  std::pair<Score, Score> run(bool hull, const std::vector<int64_t>& frames) {
    const Studio s = make_studio();
    sim::StudioOptions o;
    o.threads = 2;
    auto studio = sim::SimulatedStudio::create(s.cameras, o).value();
    o.threads = 1;
    auto held = sim::SimulatedStudio::create({s.held}, o).value();
    TexturerOptions to;
    if (!hull) to.inflate_m = 0;  // the true surface has no facets to push out
    auto texturer = ActorTexturer::create(to).value();
    auto target = scene_render::RenderTarget::create(kW, kH).value();
    std::vector<StudioCameraPose> poses;
    for (const Camera& c : s.cameras) poses.push_back({c.id, c.centre_in_world()});
    const DrawView view{
        scene::perspective(s.fov_deg * std::numbers::pi / 180, double(kW) / kH, 0.05, 200.0) *
            scene::look_at(s.eye, s.target),
        s.eye, kW, kH};
    Score nearest_score, blend_score;
    std::vector<Image<Rgb8>> images;
    std::vector<Mask> masks;
    Image<Rgb8> truth;
    Mask truth_mask;
    std::vector<uint8_t> rgba;
    for (const int64_t f : frames) {
      const sim::FrameTruth t = studio.render_all(f, &images, &masks);
      held.render(0, f, &truth, &truth_mask);
      const scene::ActorMesh mesh = hull ? hull_mesh(s.cameras, masks) : true_mesh(t.body);
      if (mesh.triangles.empty()) continue;
      EXPECT_TRUE(texturer.set_mesh(mesh).has_value());
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
      for (const auto& v : mesh.vertices) {
        lo = lo.cwiseMin(v.cast<double>());
        hi = hi.cwiseMax(v.cast<double>());
      }
      const Eigen::Vector3d centre = 0.5 * (lo + hi);
      for (const bool blend : {false, true}) {
        const auto chosen =
            blend ? preview::blend(poses, s.eye, centre) : preview::nearest(poses, s.eye, centre);
        std::array<float, ActorTexturer::kMaxCameras> w{};
        for (std::size_t i = 0; i < chosen.size(); ++i) {
          w[i] = float(chosen[i].weight);
          const int c = chosen[i].index;
          EXPECT_TRUE(texturer
                          .set_camera(int(i), s.cameras[c],
                                      reinterpret_cast<const uint8_t*>(images[c].data()))
                          .has_value());
        }
        target.bind();
        glClearColor(0, 0, 0, 0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        texturer.draw(view, blend ? TextureMode::blend : TextureMode::nearest, w,
                      blend_threshold(poses, s.eye, centre));
        target.read_rgba(rgba);
        Score& sc = blend ? blend_score : nearest_score;
        Score one;  // this frame alone
        for (int y = 0; y < kH; ++y)
          for (int x = 0; x < kW; ++x) {
            const uint8_t* p = &rgba[4 * (std::size_t(y) * kW + x)];
            const bool rendered = p[3] > 0, in_truth = truth_mask(x, y) != 0;
            if (!rendered && !in_truth) continue;
            const Rgb8 q = truth(x, y);
            const double d[3] = {double(p[0]) - q.r, double(p[1]) - q.g, double(p[2]) - q.b};
            const double e = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            sc.squared += e;
            sc.samples += 3;
            one.squared += e;
            one.samples += 3;
            if (rendered && in_truth) {
              ++sc.both;
            } else {
              ++(rendered ? sc.rendered_only : sc.true_only);
              sc.squared_edge += e;
            }
          }
        std::printf("  frame %lld %s: %.2f dB\n", (long long)f, blend ? "blend" : "nearest",
                    one.psnr());
      }
    }
    return {nearest_score, blend_score};
  }

  static void print(const char* what, const Score& n, const Score& b) {
    std::printf(
        "%s: nearest %.2f dB, blend %.2f dB; blend: %llu px in both silhouettes, %llu only "
        "rendered, %llu only true (%.0f %% of the squared error in one silhouette only)\n",
        what, n.psnr(), b.psnr(), (unsigned long long)b.both, (unsigned long long)b.rendered_only,
        (unsigned long long)b.true_only, 100 * b.edge_share());
  }

  static inline scene_render::HeadlessContext* context_ = nullptr;
};

// Frames over the sequence: walking, turning, the raised hand, crouching.
const std::vector<int64_t> kFrames{20, 60, 100, 140, 190, 240, 290, 330, 370, 420};

// Measured 27.5 dB (nearest 17.6): a quarter of the remaining error is the few silhouette pixels
// every camera sees mixed with the backing (keyed out), the rest the anti-aliased edges and the
// view-dependent light (the cameras' ring lights, spill) that three cameras only approximate.
TEST_F(PreviewQualityTest, WithTheTrueSurfaceTheBlendReaches27dB) {
  const auto [nearest, blend] = run(false, kFrames);
  print("true surface", nearest, blend);
  EXPECT_GT(blend.psnr(), nearest.psnr() + 5);
  EXPECT_GE(blend.psnr(), 27.0);
}

// Measured 20.9 dB (nearest 15.8): ~70 % of the error is in pixels of one silhouette only (the
// hull's geometry); the 28 dB needs a better surface than this visual hull.
TEST_F(PreviewQualityTest, WithTheVisualHullTheBlendBeatsNearest) {
  const auto [nearest, blend] = run(true, kFrames);
  print("visual hull", nearest, blend);
  EXPECT_GT(blend.psnr(), nearest.psnr() + 3);
  EXPECT_GE(blend.psnr(), 20.0);
}

}  // namespace
}  // namespace studio::preview

#pragma once
// The textured actor scored against a held-out camera, in process (issue 16 "quality against
// truth"), for preview_quality_test and preview_error_sources_test: the simulated studio (8 ring
// cameras + overhead, 352x288) renders each frame; the actor's true surface or the visual hull of
// the true masks (hull/ library, the node's grid 96, exact crossings) is drawn by ActorTexturer
// from the pose of a held-out camera (20 degrees between cam0 and cam1, 1.8 m high) that feeds
// nothing, and compared with that camera's image over the union of the true silhouette (the
// simulator's mask) and the rendered one (fragments drawn).
//
// Where the error is (Breakdown): the union split into
//   interior:      in both silhouettes, no 4-neighbour outside either (texturing alone);
//   rim:           in both, next to the edge of either (anti-aliased edges, spill, the keyed
//                  fringe: the texturing of silhouette pixels);
//   rendered_only: drawn where the held-out camera sees the backing (the geometry's excess);
//   true_only:     the actor where nothing was drawn (the geometry cut too deep, or discarded);
// and `unseen`: drawn pixels no selected camera coloured (counted by painting them magenta).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "actor_texturer.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "preview/camera_select.h"
#include "preview/rig_balance.h"
#include "scene/view.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "shape_prior.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "support/cameras.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

namespace studio::preview::held_out {

constexpr int kW = 352, kH = 288;

struct Region {
  uint64_t px = 0;
  double squared = 0;  // summed over the three channels
  double psnr() const { return px ? 10 * std::log10(255.0 * 255.0 * 3 * px / squared) : 0; }
};

struct Breakdown {
  Region interior, rim, rendered_only, true_only;
  uint64_t unseen = 0;
  Region total() const {
    Region t;
    for (const Region* r : {&interior, &rim, &rendered_only, &true_only}) {
      t.px += r->px;
      t.squared += r->squared;
    }
    return t;
  }
  double psnr() const { return total().psnr(); }
  double share(const Region& r) const { return r.squared / total().squared; }
  // One line: total, then per region pixels, PSNR and share of the squared error.
  std::string line() const {
    char s[400];
    auto part = [&](const Region& r) {
      char b[64];
      std::snprintf(b, sizeof b, "%6llu px %5.1f dB %3.0f%%", (unsigned long long)r.px, r.psnr(),
                    100 * share(r));
      return std::string(b);
    };
    std::snprintf(s, sizeof s,
                  "%5.2f dB | interior %s | rim %s | rendered-only %s | true-only %s "
                  "| unseen %llu px",
                  psnr(), part(interior).c_str(), part(rim).c_str(), part(rendered_only).c_str(),
                  part(true_only).c_str(), (unsigned long long)unseen);
    return s;
  }
};

// Adds one frame: `rgba` the rendered pixels, truth/truth_mask the
// held-out camera's image and true mask (top row first).
inline void accumulate(Breakdown& b, const std::vector<uint8_t>& rgba, const Image<Rgb8>& truth,
                       const Mask& truth_mask, const Eigen::Vector3f& unseen) {
  auto rendered = [&](int x, int y) { return rgba[4 * (std::size_t(y) * kW + x) + 3] > 0; };
  auto inside = [&](int x, int y) {
    return x < 0 || y < 0 || x >= kW || y >= kH || (rendered(x, y) && truth_mask(x, y) != 0);
  };
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const uint8_t* p = &rgba[4 * (std::size_t(y) * kW + x)];
      const bool r = p[3] > 0, t = truth_mask(x, y) != 0;
      if (!r && !t) continue;
      const Rgb8 q = truth(x, y);
      const double d[3] = {double(p[0]) - q.r, double(p[1]) - q.g, double(p[2]) - q.b};
      const double e = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      Region* region = &b.true_only;
      if (r && t)
        region = inside(x - 1, y) && inside(x + 1, y) && inside(x, y - 1) && inside(x, y + 1)
                     ? &b.interior
                     : &b.rim;
      else if (r)
        region = &b.rendered_only;
      ++region->px;
      region->squared += e;
      // The unseen colour, shaded (actor_texturer.cc): its channels' proportions survive.
      if (r && unseen.x() > 0.9f && unseen.y() == 0 && p[1] == 0 && p[0] > 0 && p[0] == p[2])
        ++b.unseen;
    }
}

struct Studio {
  std::vector<Camera> cameras;
  std::vector<StudioCameraPose> poses;
  Camera held;
  Eigen::Vector3d eye, target{0, 1.1, 0};
  DrawView view;
};

// `count` cameras: count - 1 on the ring, one overhead (default 8 + 1).
// The held-out camera at azimuth `held_az_deg` (cam0 at 0, cam1 at 360 / (count - 1)), height
// `held_y` m, 3.6 m from the centre's axis, looking at (0, 1.1, 0).
inline Studio make_studio(int count = 9, double held_az_deg = 20, double held_y = 1.8) {
  sim::RingOptions r;
  r.count = count;
  r.width = kW;
  r.height = kH;
  r.focal_px *= double(kW) / 704.0;
  Studio s;
  s.cameras = sim::ring_cameras(r);
  for (const Camera& c : s.cameras) s.poses.push_back({c.id, c.centre_in_world()});
  const double az = held_az_deg * std::numbers::pi / 180;
  s.eye = {3.6 * std::sin(az), held_y, 3.6 * std::cos(az)};
  const double focal = 560.0 * kW / 704.0;
  s.held =
      support::look_at_camera("held", s.eye, s.target, Eigen::Vector3d::UnitY(), kW, kH, focal);
  const double fov = 2 * std::atan(0.5 * kH / focal);
  s.view = {scene::perspective(fov, double(kW) / kH, 0.05, 200.0) * scene::look_at(s.eye, s.target),
            s.eye, kW, kH};
  return s;
}

inline scene::ActorMesh hull_mesh(const std::vector<Camera>& cameras,
                                  const std::vector<Mask>& masks, int cells = 96) {
  std::vector<RunMask> runs;
  for (const Mask& m : masks) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<hull::View> views;
  for (std::size_t c = 0; c < cameras.size(); ++c) views.push_back({&cameras[c], &runs[c]});
  hull::GridSpec g;  // the preview studio test's hull.yaml
  g.box_min = {-1.5, 0.0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.cells_u = g.cells_v = cells;
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

inline scene::ActorMesh true_mesh(const sim::ActorBody& body) {
  const sim::TriangleMesh m = body.mesh(64);
  scene::ActorMesh out;
  out.actor_id = "actor0";
  out.vertices = m.vertices;
  out.triangles = m.triangles;
  out.compute_normals();
  return out;
}

// One way to texture a frame: nearest (the camera nearest in angle, or `camera` forced) or the
// blend of the k nearest.
struct Variant {
  std::string name;
  TextureMode mode = TextureMode::blend;
  int camera = -1;  // nearest: this camera instead of the nearest one
};

struct Scoring {
  bool hull = false;       // geometry: the visual hull of the true masks, else the true surface
  sim::StudioOptions sim;  // the realism knobs, for the feeding cameras and the held-out one
  TexturerOptions texturer;
  int cameras = 9;                        // studio cameras: cameras - 1 on the ring + overhead
  double held_az_deg = 20, held_y = 1.8;  // the held-out camera (make_studio)
  int hull_cells = 96;   // the hull's grid (cells along x and z), as the node's `grid`
  bool verbose = false;  // per frame PSNR
  std::string dump_dir;  // when set: <frame>_truth.png and <frame>_<variant>.png there
  // The shape prior on the hull (testing/shape_prior.h), anchored at the rims of the texturing
  // cameras (the images a node would have), or of every studio camera when shape_all_cameras.
  ShapePriorOptions shape;
  bool shape_all_cameras = false;
  // Blend's carving also against every studio camera's mask (the true masks the hull was built
  // from; ActorTexturer::set_carving_masks).
  bool carve_all_cameras = false;
  // The cameras' colour balance as the node learns it (preview/rig_balance.h): every frame pools
  // the blend's texturing cameras' images and masks of that frame, then every variant draws with
  // the gains so far. `balances` (when set) receives the balance after each frame.
  bool balance = false;
  // Pool every studio camera's image of the frame, not only the blend's (the node's rig samples).
  bool balance_all_cameras = false;
  std::vector<offline::ColourBalance>* balances = nullptr;
  // Frames pooled before the scored ones (a preview that has been running: RigBalance applies
  // its gains once 8 frames are pooled).
  std::vector<int64_t> balance_warmup;
};

// Scores every variant over `frames` (a current GL context is needed).
inline std::vector<Breakdown> evaluate(const Scoring& setup, const std::vector<Variant>& variants,
                                       const std::vector<int64_t>& frames) {
  const Studio s = make_studio(setup.cameras, setup.held_az_deg, setup.held_y);
  sim::StudioOptions o = setup.sim;
  o.threads = 2;
  auto studio = sim::SimulatedStudio::create(s.cameras, o).value();
  o.threads = 1;
  o.camera_response.clear();  // the held-out camera: the reference response (1, 1, 1)
  auto held = sim::SimulatedStudio::create({s.held}, o).value();
  std::map<std::string, Camera> rig;
  for (const Camera& c : s.cameras) rig[c.id] = c;
  RigBalance balance;
  TexturerOptions to = setup.texturer;
  if (!setup.hull) to.inflate_m = 0;  // the true surface has no facets to push out
  auto texturer = ActorTexturer::create(to).value();
  auto target = scene_render::RenderTarget::create(kW, kH).value();
  std::vector<Breakdown> out(variants.size());
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  Image<Rgb8> truth;
  Mask truth_mask;
  std::vector<uint8_t> rgba;
  // The frame's mesh (empty when the actor is not seen) and its centre.
  auto mesh_of = [&](const sim::FrameTruth& t, Eigen::Vector3d* centre) {
    const scene::ActorMesh mesh =
        setup.hull ? hull_mesh(s.cameras, masks, setup.hull_cells) : true_mesh(t.body);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    for (const auto& v : mesh.vertices) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
    *centre = 0.5 * (lo + hi);
    return mesh;
  };
  // Pools the frame's blend cameras into the balance, as the node does.
  auto pool = [&](const scene::ActorMesh& mesh, const Eigen::Vector3d& centre) {
    std::vector<RunMask> runs;
    std::vector<BalanceView> views;
    runs.reserve(s.cameras.size());
    std::vector<int> pooled;
    if (setup.balance_all_cameras)
      for (std::size_t c = 0; c < s.cameras.size(); ++c) pooled.push_back(int(c));
    else
      for (const CameraWeight& c : preview::blend(s.poses, s.eye, centre))
        pooled.push_back(c.index);
    for (const int c : pooled) {
      runs.push_back(RunMask::from_mask(masks[c].view()));
      views.push_back({s.cameras[c].id, images[c].view(), &runs.back()});
    }
    EXPECT_TRUE(balance.add(rig, mesh, views).has_value());
    if (setup.balances) setup.balances->push_back(balance.balance());
  };
  if (setup.balance)
    for (const int64_t f : setup.balance_warmup) {
      const sim::FrameTruth t = studio.render_all(f, &images, &masks);
      Eigen::Vector3d centre;
      const scene::ActorMesh mesh = mesh_of(t, &centre);
      if (!mesh.triangles.empty()) pool(mesh, centre);
    }
  for (const int64_t f : frames) {
    const sim::FrameTruth t = studio.render_all(f, &images, &masks);
    held.render(0, f, &truth, &truth_mask);
    Eigen::Vector3d centre;
    const scene::ActorMesh mesh = mesh_of(t, &centre);
    if (mesh.triangles.empty()) continue;
    if (setup.balance) pool(mesh, centre);
    for (std::size_t v = 0; v < variants.size(); ++v) {
      const Variant& var = variants[v];
      const bool blend = var.mode == TextureMode::blend;
      std::vector<CameraWeight> chosen =
          blend ? preview::blend(s.poses, s.eye, centre) : preview::nearest(s.poses, s.eye, centre);
      if (!blend && var.camera >= 0) chosen = {{var.camera, 0, 1}};
      scene::ActorMesh drawn = mesh;
      if (setup.shape.steps > 0) {
        std::vector<KeyedView> kv;
        if (setup.shape_all_cameras)
          for (std::size_t c = 0; c < s.cameras.size(); ++c)
            kv.push_back({&s.cameras[c], reinterpret_cast<const uint8_t*>(images[c].data())});
        else
          for (const CameraWeight& c : chosen)
            kv.push_back(
                {&s.cameras[c.index], reinterpret_cast<const uint8_t*>(images[c.index].data())});
        apply_shape_prior(drawn, kv, setup.shape);
      }
      EXPECT_TRUE(texturer.set_mesh(drawn).has_value());
      std::vector<ActorTexturer::CarvingMask> carving;
      if (setup.carve_all_cameras)
        for (std::size_t c = 0; c < s.cameras.size(); ++c)
          carving.push_back({&s.cameras[c], masks[c].data()});
      EXPECT_TRUE(texturer.set_carving_masks(carving).has_value());
      std::array<float, ActorTexturer::kMaxCameras> w{};
      for (std::size_t i = 0; i < chosen.size(); ++i) {
        w[i] = float(chosen[i].weight);
        const int c = chosen[i].index;
        EXPECT_TRUE(texturer
                        .set_camera(int(i), s.cameras[c],
                                    reinterpret_cast<const uint8_t*>(images[c].data()),
                                    balance.gains(s.cameras[c].id))
                        .has_value());
      }
      target.bind();
      glClearColor(0, 0, 0, 0);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      texturer.draw(s.view, var.mode, w, blend_threshold(s.poses, s.eye, centre));
      target.read_rgba(rgba);
      if (!setup.dump_dir.empty()) {
        cv::Mat r(kH, kW, CV_8UC4, rgba.data()), bgr;
        cv::cvtColor(r, bgr, cv::COLOR_RGBA2BGR);
        cv::Mat t(kH, kW, CV_8UC3, truth.data()), tb;
        cv::cvtColor(t, tb, cv::COLOR_RGB2BGR);
        // The actor's box, truth beside the rendering, 3x.
        cv::Mat m(kH, kW, CV_8UC1, truth_mask.data());
        const cv::Rect box = cv::boundingRect(m) + cv::Size(8, 8) - cv::Point(4, 4);
        const cv::Rect roi = box & cv::Rect(0, 0, kW, kH);
        cv::Mat pair, big;
        cv::Mat diff;
        cv::absdiff(tb(roi), bgr(roi), diff);
        diff *= 4;
        cv::hconcat(std::vector<cv::Mat>{tb(roi), bgr(roi), diff}, pair);
        cv::resize(pair, big, {}, 3, 3, cv::INTER_NEAREST);
        cv::imwrite(setup.dump_dir + "/" + std::to_string(f) + "_" + var.name + ".png", big);
      }
      Breakdown one;
      accumulate(one, rgba, truth, truth_mask, to.unseen);
      accumulate(out[v], rgba, truth, truth_mask, to.unseen);
      if (setup.verbose)
        std::printf("  frame %lld %s: %s\n", (long long)f, var.name.c_str(), one.line().c_str());
    }
  }
  return out;
}

// Frames over the actor's sequence: walking, turning, the raised hand, crouching.
inline const std::vector<int64_t> kFrames{20, 60, 100, 140, 190, 240, 290, 330, 370, 420};

// A suite that scores against the held-out camera: one headless EGL context, current for every
// test of the suite (the scoring renders in this process).
class HeldOutTest : public ::testing::Test {
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

 private:
  static inline scene_render::HeadlessContext* context_ = nullptr;
};

}  // namespace studio::preview::held_out

// The projector's scene cache on Mesa llvmpipe (issue 15: render the scene only when it changes;
// projector/static_shift.h, render/static_layer.h), both forms, 1920x1080:
// - markers (small unlit squares) in front of and behind the screen, all static: from an eye
//   moved in random directions by 95 % of the allowed move, the frame restored from the cache and
//   a full render from the moved eye put every marker's centroid within max_error_px (0.5 px) of
//   each other. Control: a move of 4x the allowed move re-renders (the frame equals the full
//   render) and the frame from the first eye is > 0.5 px off there — the comparison can fail;
// - a moving node (a marker changed every frame) is drawn where it is in every cached frame;
// - a new static version re-renders;
// - hold_frames: a walking eye served by the layer between redraws, within the reported bound;
// - the default museum: cached vs full render from a moved eye under the bound, PSNR.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <opencv2/core.hpp>
#include <random>

#include "projector_render/frame_renderer.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "testing/projectors.h"

using namespace studio;
using namespace studio::projector_render;

namespace {

scene_render::HeadlessContext& context() {
  static auto* c =
      new scene_render::HeadlessContext(scene_render::HeadlessContext::create().value());
  return *c;
}

// Where the ray from the eye through x meets the plane of the raw corners.
Eigen::Vector3d on_screen(const Projector& p, const Eigen::Vector3d& eye,
                          const Eigen::Vector3d& x) {
  const Eigen::Vector3d n =
      (p.screen[1] - p.screen[0]).cross(p.screen[3] - p.screen[0]).normalized();
  return eye + n.dot(p.screen[0] - eye) / n.dot(x - eye) * (x - eye);
}

scene_assets::Asset square_asset() {
  scene_assets::Asset a;
  a.path = "test:square";
  a.sha256 = "square";
  scene_assets::MeshData m;
  m.positions = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
  m.normals.assign(4, Eigen::Vector3f::UnitZ());
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = 0;
  scene_assets::MaterialData mat;
  mat.double_sided = true;
  a.materials.push_back(mat);
  a.meshes.push_back(m);
  return a;
}

scene::Node marker(const std::string& id, const Eigen::Vector3d& x, const Eigen::Vector3d& eye,
                   double scale) {
  scene::Node n;
  n.id = id;
  n.kind = scene::NodeKind::model;
  n.asset = {"test:square", "square", {}};
  n.material.high_contrast = true;  // unlit white
  n.local.translation = x;
  // Facing the eye, rolled 0.5 rad: no edge runs along a pixel row or column, so the centroid
  // of the rasterised square follows sub-pixel moves (an axis-aligned one jumps by 0.5 px).
  n.local.rotation =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), (eye - x).normalized()) *
      Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());
  n.local.scale = Eigen::Vector3d::Constant(scale);
  return n;
}

// Intensity-weighted centroid (red channel) in a 41 x 41 window; nullopt when nearly empty.
std::optional<Eigen::Vector2d> centroid(const std::vector<std::uint8_t>& rgba, int w, int h,
                                        const Eigen::Vector2d& around) {
  double sw = 0, sx = 0, sy = 0;
  for (int y = int(around.y()) - 20; y <= int(around.y()) + 20; ++y)
    for (int x = int(around.x()) - 20; x <= int(around.x()) + 20; ++x) {
      if (y < 0 || x < 0 || y >= h || x >= w) continue;
      const double v = rgba[(std::size_t(y) * w + x) * 4];
      sw += v;
      sx += v * x;
      sy += v * y;
    }
  if (sw < 255.0 * 20) return std::nullopt;
  return Eigen::Vector2d(sx / sw, sy / sw);
}

struct Markers {
  scene::Scene scene;
  std::vector<Eigen::Vector3d> points;
};

// 14 markers seen through the screen from `eye`, 0.45..2.6 times the eye-to-screen distance
// along their rays (in front of and behind the screen), apart in the projector image.
Markers make_markers(const Projector& p, const Eigen::Vector3d& eye, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Markers m;
  while (m.points.size() < 14) {
    const Eigen::Vector3d on = p.screen[0] + (0.1 + 0.8 * u(rng)) * (p.screen[1] - p.screen[0]) +
                               (0.1 + 0.8 * u(rng)) * (p.screen[3] - p.screen[0]);
    const double depth = m.points.size() == 0 ? 0.45 : m.points.size() == 1 ? 2.6
                                                                             : 0.45 + 2.15 * u(rng);
    const Eigen::Vector3d x = eye + depth * (on - eye);
    Eigen::Vector2d px;
    if (!p.camera.project(on, &px)) continue;
    bool apart = true;
    for (const auto& q : m.points) {
      Eigen::Vector2d qx;
      p.camera.project(on_screen(p, eye, q), &qx);
      apart = apart && (qx - px).norm() > 70;
    }
    if (!apart) continue;
    m.points.push_back(x);
    const double scale = 0.045 * (x - eye).norm() / (on - eye).norm();
    const std::string id = "marker" + std::to_string(m.points.size());
    EXPECT_TRUE(m.scene.apply({0, scene::AddNode{marker(id, x, eye, scale)}}));
  }
  return m;
}

std::vector<std::uint8_t> frame_of(FrameRenderer& fr) {
  fr.finish();
  Readback rb;
  fr.read(rb, true);
  return rb.rgba;
}

// Largest centroid distance between two frames over the markers (around where they are from eye).
double worst_marker_distance(const Projector& p, const Markers& m, const Eigen::Vector3d& eye,
                             const std::vector<std::uint8_t>& a,
                             const std::vector<std::uint8_t>& b) {
  double worst = 0;
  for (const auto& x : m.points) {
    Eigen::Vector2d want;
    EXPECT_TRUE(p.camera.project(on_screen(p, eye, x), &want));
    auto ca = centroid(a, p.camera.width, p.camera.height, want);
    auto cb = centroid(b, p.camera.width, p.camera.height, want);
    if (!ca || !cb) {
      ADD_FAILURE() << "marker missing near " << want.transpose();
      continue;
    }
    worst = std::max(worst, (*ca - *cb).norm());
  }
  return worst;
}

const char* name(Form f) { return f == Form::single_pass ? "single pass" : "two pass"; }

TEST(SceneCache, CachedFrameKeepsEveryStaticPointWithinTheSetPixelsOfAFullRender) {
  (void)context();
  const Projector p = projector::testing::studio_projectors()[0];  // back wall, 1920x1080
  auto view = projector::ProjectorView::create(p).value();
  std::mt19937 rng(15);
  std::normal_distribution<double> g(0, 1);
  const Eigen::Vector3d eye0(0.2, 1.6, 1.0);
  const Markers m = make_markers(p, eye0, rng);
  const scene::Scene empty;
  for (Form form : {Form::single_pass, Form::two_pass}) {
    FrameRendererOptions fo;
    fo.form = form;
    fo.renderer.clear_colour = {0, 0, 0, 1};
    fo.thumb_width = fo.thumb_height = 0;
    auto fr = FrameRenderer::create(view, fo);
    ASSERT_TRUE(fr) << fr.error().message;
    ASSERT_TRUE(fr->renderer().upload(square_asset()));
    const LayeredScene layered{m.scene, 1, &empty};
    auto first = fr->render(layered, eye0, {});
    ASSERT_TRUE(first) << first.error().message;
    EXPECT_FALSE(first->from_cache);
    const auto at_eye0 = frame_of(*fr);
    const double allowed = fr->cache_allowed_move_m(eye0);
    ASSERT_GT(allowed, 0);
    double worst = 0;
    for (int k = 0; k < 6; ++k) {
      const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
      const Eigen::Vector3d eye1 = eye0 + 0.95 * allowed * d;
      auto info = fr->render(layered, eye1, {});
      ASSERT_TRUE(info);
      ASSERT_TRUE(info->from_cache) << "bound " << info->shift_px << " px";
      const auto cached = frame_of(*fr);
      ASSERT_TRUE(fr->render(m.scene, eye1, {}));  // the full render (no cache)
      const auto full = frame_of(*fr);
      worst = std::max(worst, worst_marker_distance(p, m, eye1, cached, full));
    }
    // Control: 4x the allowed move along the screen re-renders, and the first eye's frame is
    // visibly off there.
    const Eigen::Vector3d far_eye = eye0 + 4 * allowed * view.screen().right;
    auto info = fr->render(layered, far_eye, {});
    ASSERT_TRUE(info);
    EXPECT_FALSE(info->from_cache);
    EXPECT_GT(info->shift_px, fo.scene_cache.max_error_px);
    const auto rerendered = frame_of(*fr);
    ASSERT_TRUE(fr->render(m.scene, far_eye, {}));
    const auto full = frame_of(*fr);
    EXPECT_EQ(rerendered, full);
    const double control = worst_marker_distance(p, m, far_eye, at_eye0, full);
    std::printf("%s: allowed eye move %.2f mm, worst marker distance cached vs full %.3f px; "
                "control (4x move): %.3f px\n",
                name(form), allowed * 1e3, worst, control);
    EXPECT_LE(worst, fo.scene_cache.max_error_px);
    EXPECT_GT(control, fo.scene_cache.max_error_px);
  }
}

TEST(SceneCache, MovingNodeIsDrawnEveryFrameAndANewStaticVersionReRenders) {
  (void)context();
  const Projector p = projector::testing::studio_projectors()[0];
  auto view = projector::ProjectorView::create(p).value();
  std::mt19937 rng(3);
  const Eigen::Vector3d eye(0.2, 1.6, 1.0);
  const Markers m = make_markers(p, eye, rng);
  for (Form form : {Form::single_pass, Form::two_pass}) {
    FrameRendererOptions fo;
    fo.form = form;
    fo.renderer.clear_colour = {0, 0, 0, 1};
    fo.thumb_width = fo.thumb_height = 0;
    auto fr = FrameRenderer::create(view, fo);
    ASSERT_TRUE(fr) << fr.error().message;
    ASSERT_TRUE(fr->renderer().upload(square_asset()));
    int cached = 0;
    double worst = 0;
    for (int frame = 0; frame < 8; ++frame) {
      // The moving marker crosses the screen, 1 m behind it.
      const Eigen::Vector3d x = p.screen[0] + (0.15 + 0.1 * frame) * (p.screen[1] - p.screen[0]) +
                                0.3 * (p.screen[3] - p.screen[0]) + Eigen::Vector3d(0, 0, -1);
      scene::Scene moving;
      ASSERT_TRUE(moving.apply({0, scene::AddNode{marker("flyer", x, eye, 0.05)}}));
      auto info = fr->render(LayeredScene{m.scene, 7, &moving}, eye, {});
      ASSERT_TRUE(info);
      cached += info->from_cache;
      const auto got = frame_of(*fr);
      scene::Scene all = m.scene;
      ASSERT_TRUE(all.apply({0, scene::AddNode{marker("flyer", x, eye, 0.05)}}));
      ASSERT_TRUE(fr->render(all, eye, {}));
      const auto want = frame_of(*fr);
      Eigen::Vector2d px;
      ASSERT_TRUE(p.camera.project(on_screen(p, eye, x), &px));
      auto cg = centroid(got, p.camera.width, p.camera.height, px);
      auto cw = centroid(want, p.camera.width, p.camera.height, px);
      ASSERT_TRUE(cg && cw) << "frame " << frame;
      worst = std::max(worst, (*cg - *cw).norm());
      EXPECT_EQ(got, want) << "frame " << frame;  // the same eye: the same frame exactly
    }
    EXPECT_EQ(cached, 7);  // all but the first
    EXPECT_LT(worst, 0.01);
    // A new static version (a static node changed) re-renders.
    auto info = fr->render(LayeredScene{m.scene, 8, nullptr}, eye, {});
    ASSERT_TRUE(info);
    EXPECT_FALSE(info->from_cache);
    info = fr->render(LayeredScene{m.scene, 8, nullptr}, eye, {});
    ASSERT_TRUE(info);
    EXPECT_TRUE(info->from_cache);
    std::printf("%s: %d of 8 frames from the cache, the moving marker within %.3f px\n",
                name(form), cached, worst);
  }
}

// An eye moving more than the bound every frame re-renders without keeping the layer (it would
// not serve the next frame); once the eye stops, the layer is kept and the next frame reuses it.
TEST(SceneCache, MovingEyeDoesNotKeepTheLayerAStillEyeDoes) {
  (void)context();
  const Projector p = projector::testing::studio_projectors()[0];
  auto view = projector::ProjectorView::create(p).value();
  std::mt19937 rng(4);
  const Eigen::Vector3d eye(0.2, 1.6, 1.0);
  const Markers m = make_markers(p, eye, rng);
  FrameRendererOptions fo;
  fo.thumb_width = fo.thumb_height = 0;
  auto fr = FrameRenderer::create(view, fo);
  ASSERT_TRUE(fr) << fr.error().message;
  ASSERT_TRUE(fr->renderer().upload(square_asset()));
  const LayeredScene layered{m.scene, 1, nullptr};
  std::vector<FrameInfo> infos;
  for (int k = 0; k < 6; ++k)  // walking: 5 mm per frame
    infos.push_back(fr->render(layered, eye + Eigen::Vector3d(0.005 * k, 0, 0), {}).value());
  for (int k = 0; k < 3; ++k)  // stopped
    infos.push_back(fr->render(layered, eye + Eigen::Vector3d(0.025, 0, 0), {}).value());
  EXPECT_TRUE(infos[0].stored);  // nothing cached yet
  for (int k = 1; k < 6; ++k) {
    EXPECT_FALSE(infos[k].from_cache) << k;
    EXPECT_FALSE(infos[k].stored) << k;
  }
  EXPECT_FALSE(infos[6].from_cache);  // the first frame at rest: re-rendered and kept
  EXPECT_TRUE(infos[6].stored);
  EXPECT_TRUE(infos[7].from_cache);
  EXPECT_TRUE(infos[8].from_cache);
}

// hold_frames (CPU-only projector PCs): an eye walking 5 mm a frame (5-10x the bound) gets the
// layer drawn every hold_frames + 1 frames and restored in between: a held frame is exactly the
// full render from the eye that drew the layer, and every marker lies within the frame's
// reported bound (FrameInfo::shift_px) of a full render from the current eye, a bound beyond
// max_error_px (the frame really is off by more than the cache otherwise allows). Control:
// hold_frames 0 draws every frame of the walk.
TEST(SceneCache, HoldServesAWalkingEyeThenRedrawsWithinTheReportedBound) {
  (void)context();
  const Projector p = projector::testing::studio_projectors()[0];
  auto view = projector::ProjectorView::create(p).value();
  std::mt19937 rng(16);
  const Eigen::Vector3d eye0(0.2, 1.6, 1.0);
  const Markers m = make_markers(p, eye0, rng);
  const scene::Scene empty;
  for (Form form : {Form::single_pass, Form::two_pass}) {
    for (int hold : {2, 0}) {
      FrameRendererOptions fo;
      fo.form = form;
      fo.renderer.clear_colour = {0, 0, 0, 1};
      fo.thumb_width = fo.thumb_height = 0;
      fo.scene_cache.hold_frames = hold;
      auto fr = FrameRenderer::create(view, fo);
      ASSERT_TRUE(fr) << fr.error().message;
      ASSERT_TRUE(fr->renderer().upload(square_asset()));
      const LayeredScene layered{m.scene, 1, &empty};
      Eigen::Vector3d drawn_from = eye0;
      int held = 0;
      double worst_excess = -1e9, smallest_bound = 1e9;
      for (int k = 0; k < 9; ++k) {
        const Eigen::Vector3d eye = eye0 + 0.005 * k * view.screen().right;
        auto info = fr->render(layered, eye, {});
        ASSERT_TRUE(info) << info.error().message;
        const bool want_held = hold > 0 && k % (hold + 1) != 0;
        EXPECT_EQ(info->from_cache, want_held) << name(form) << " hold " << hold << " frame " << k;
        EXPECT_EQ(info->held, want_held) << name(form) << " hold " << hold << " frame " << k;
        if (!info->held) {
          drawn_from = eye;
          continue;
        }
        ++held;
        const auto got = frame_of(*fr);
        ASSERT_TRUE(fr->render(m.scene, drawn_from, {}));
        EXPECT_EQ(got, frame_of(*fr)) << "frame " << k << ": not the layer drawn from its eye";
        ASSERT_TRUE(fr->render(m.scene, eye, {}));
        const auto full = frame_of(*fr);
        worst_excess =
            std::max(worst_excess, worst_marker_distance(p, m, eye, got, full) - info->shift_px);
        smallest_bound = std::min(smallest_bound, info->shift_px);
      }
      if (hold == 0) {
        EXPECT_EQ(held, 0);
        continue;
      }
      std::printf("%s, hold %d: %d of 9 walking frames held, bound %.2f px at least, markers "
                  "within the bound by %.3f px\n",
                  name(form), hold, held, smallest_bound, -worst_excess);
      EXPECT_EQ(held, 6);
      EXPECT_LE(worst_excess, 0.0);
      EXPECT_GT(smallest_bound, fo.scene_cache.max_error_px);
    }
  }
}

TEST(SceneCache, DefaultMuseumFromTheCacheMatchesAFullRender) {
  (void)context();
  const Projector p = projector::testing::studio_projectors()[0];
  auto view = projector::ProjectorView::create(p).value();
  auto d = scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml");
  ASSERT_TRUE(d) << d.error().message;
  scene_assets::AssetCache cache;
  auto scene = scene_assets::build_scene(*d, cache, 0);
  ASSERT_TRUE(scene) << scene.error().message;
  const Eigen::Vector3d eye0(0.3, 1.7, 1.0);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  for (Form form : {Form::single_pass, Form::two_pass}) {
    FrameRendererOptions fo;
    fo.form = form;
    auto fr = FrameRenderer::create(view, fo);
    ASSERT_TRUE(fr) << fr.error().message;
    for (const auto& [path, a] : cache.all()) ASSERT_TRUE(fr->renderer().upload(*a));
    const LayeredScene layered{*scene, 1, nullptr};
    ASSERT_TRUE(fr->render(layered, eye0, {}));
    const double allowed = fr->cache_allowed_move_m(eye0);
    ASSERT_GT(allowed, 0);
    double worst = 1e9;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d eye1 =
          eye0 + 0.95 * allowed * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
      auto info = fr->render(layered, eye1, {});
      ASSERT_TRUE(info);
      ASSERT_TRUE(info->from_cache);
      const auto cached = frame_of(*fr);
      ASSERT_TRUE(fr->render(*scene, eye1, {}));
      const auto full = frame_of(*fr);
      const cv::Mat a(p.camera.height, p.camera.width, CV_8UC4, (void*)cached.data()),
          b(p.camera.height, p.camera.width, CV_8UC4, (void*)full.data());
      worst = std::min(worst, cv::PSNR(a, b));
    }
    std::printf("%s: museum, allowed eye move %.2f mm, worst PSNR cached vs full %.1f dB\n",
                name(form), allowed * 1e3, worst);
    EXPECT_GE(worst, 40.0);
  }
}

}  // namespace

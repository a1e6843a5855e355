// A projector frame on Mesa llvmpipe (EGL surfaceless) at 1920x1080 (issue 15 figure): the
// default demo scene from an actor's eye through the back-wall projector's screen, plus the
// simulated actor's mesh grown by a 2 cm margin and drawn black (the mask), in both forms:
// single pass (the paper's) and two pass (eye texture + warp; the warp's extra cost is the
// difference). Baselines in the same run: clear only, and the same scene drawn once from a plain
// perspective camera at the eye (what any renderer of the scene pays). `Readback` adds what the
// node does per published frame: read back, blackout mask to runs, thumbnail. `Pipelined` is
// the single pass with one frame in flight (fence on the previous frame instead of glFinish):
// the throughput when binning of a frame overlaps the shading of the one before. `TwoPassFullWarp`
// is the two pass with the warp over the whole frame (the baseline of warp_screen_only);
// `SinglePassBilinear` samples textures bilinearly (the baseline of the projector's nearest
// texels). The plain scene is drawn with the projector's renderer options. `GrowMask`
// is the CPU part of the mask alone (grow_mesh per frame, on the calling thread, inside the frame
// cases). Scene cache (issue 15: render the scene only when it changes): `SinglePassCached` and
// `TwoPassCached` split the scene into still (everything but the animated flyer) and moving (the
// flyer) every frame, as the node does (projector/scene_layers.h), and render it layered from a
// still eye: the static layer is restored from the cache (one blit of colour + depth), the flyer
// and the mask drawn over it — the frame the node renders while the eye stays within the bound.
// `SinglePassCacheMiss`: the same with the eye moving 6 mm every frame (on a 2 cm circle; the
// bound is ~0.6 mm here): every frame re-renders the static layer (and does not keep it: the
// eye is not still) — the cost of a frame when the cache never survives (a walking actor). The
// `_720p` variants render the same at 1280x720 (the demo's projector size; the intrinsics scaled
// by 2/3). Late latching (the node's default): `LateLatch_720p` times only what a new mesh
// waits for — the mask grown, drawn over the scene prepared ahead, finished and read back —
// with the scene drawn ahead (FrameRenderer::prepare) and finished outside the timing
// (PauseTiming); its baseline in the same run is `SinglePassReadback_720p`, the whole frame
// after the mesh (scene + mask + finish + read-back). Counters: shaded_per_px (fragments past the depth test in one frame / pixels: the
// overdraw llvmpipe shades; 1.0 = once per pixel), triangles (submitted in the last frame),
// from_cache (cached cases: the fraction of frames whose static layer came from the cache).
// `TwoPass_720p` / `TwoPassHalfEye_720p`: the two pass at 1280x720 with the eye texture at its
// suggested size and at half of it each side (FrameRendererOptions::eye_texture_scale 0.5: a
// quarter of the scene's fragments; baseline `SinglePass_720p`). `HullMask_720p`: the mask of the
// hull's own mesh per simplification setting (after BM_HullMask_720p below). `SinglePassHold`,
// `TwoPassHold` (1920x1080) and `SinglePassHold_720p`: the cache miss's walking eye with
// scene_cache.hold_frames = the argument (0: the cache miss itself, the baseline).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <benchmark/benchmark.h>

#include <numbers>
#include <optional>
#include <opencv2/imgproc.hpp>
#include <set>

#include "projector/mask_geometry.h"
#include "projector/scene_layers.h"
#include "projector_render/frame_renderer.h"
#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "sim/actor.h"
#include "testing/hull_meshes.h"
#include "testing/projectors.h"

using namespace studio;
using namespace studio::projector_render;

namespace {

const Eigen::Vector3d kEye(0.1, 1.65, 1.2);

struct Fixture {
  scene_render::HeadlessContext context;
  scene_assets::AssetCache cache;
  scene::Scene scene;
  Projector projector;
  projector::ActorMesh actor;
  std::set<scene::NodeId> moving;  // the animated nodes
};

Fixture& fixture() {
  static Fixture* f = [] {
    auto ctx = scene_render::HeadlessContext::create();
    if (!ctx) throw std::runtime_error(ctx.error().message);
    auto d = scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml");
    if (!d) throw std::runtime_error(d.error().message);
    scene_assets::AssetCache cache;
    auto s = scene_assets::build_scene(*d, cache);
    if (!s) throw std::runtime_error(s.error().message);
    // The simulated actor (walking, 2 s in), between the eye and the back wall.
    sim::Actor::Options ao;
    ao.motion = sim::Motion::walk;
    const sim::TriangleMesh body = sim::Actor(ao).body_at(2.0).mesh(16);
    projector::ActorMesh actor;
    for (const auto& v : body.vertices) actor.vertices.push_back(v + Eigen::Vector3f(0, 0, -0.8f));
    actor.triangles = body.triangles;
    std::set<scene::NodeId> moving;
    for (const auto& [name, a] : s->animations())
      for (const auto& t : a.animation.tracks) moving.insert(t.node);
    return new Fixture{std::move(*ctx),    std::move(cache),  std::move(*s),
                       projector::testing::studio_projectors()[0], std::move(actor),
                       std::move(moving)};
  }();
  return *f;
}

enum class Work {
  clear,
  grow_mask,
  plain,
  single_pass,
  single_pass_bilinear,
  single_pass_pipelined,
  single_pass_pipelined_no_mask,  // the floor: the scene through the screen, no actor mask
  single_pass_pipelined_outline,  // the node's default mask: grown by its outline, rects cleared
  single_pass_pipelined_outline_last,  // the same, masks_first off (the baseline)
  two_pass,
  two_pass_full_warp,
  single_pass_readback,
  single_pass_cached,
  single_pass_cache_miss,
  two_pass_cached,
  two_pass_half_eye,
  late_latch,
  single_pass_hold,  // the cache miss's walking eye with scene_cache.hold_frames = state.range(0)
  two_pass_hold
};

// The back-wall projector at 1280x720 (intrinsics scaled about the pixel-centre convention).
Projector at_720p(Projector p) {
  Camera& c = p.camera;
  const double k = 1280.0 / c.width;
  c.width = 1280;
  c.height = 720;
  c.intrinsics.fx *= k;
  c.intrinsics.fy *= k;
  c.intrinsics.cx = (c.intrinsics.cx + 0.5) * k - 0.5;
  c.intrinsics.cy = (c.intrinsics.cy + 0.5) * k - 0.5;
  return p;
}

// Fragments that passed the depth test (llvmpipe shades those: early depth test) in one frame,
// over the frame's pixel count: 1.0 = every pixel shaded once.
template <class Draw>
double shaded_per_pixel(double pixels, Draw&& draw) {
  GLuint query = 0;
  glGenQueries(1, &query);
  glBeginQuery(GL_SAMPLES_PASSED, query);
  draw();
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint64 samples = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &samples);
  glDeleteQueries(1, &query);
  return static_cast<double>(samples) / pixels;
}

void run(benchmark::State& state, Work work, bool hd720 = false) {
  Fixture& f = fixture();
  const Projector projector = hd720 ? at_720p(f.projector) : f.projector;
  auto view = projector::ProjectorView::create(projector);
  FrameRendererOptions fo;
  const bool two_pass = work == Work::two_pass || work == Work::two_pass_full_warp ||
                        work == Work::two_pass_half_eye ||
                        work == Work::two_pass_cached || work == Work::two_pass_hold;
  const bool layered = work == Work::single_pass_cached || work == Work::single_pass_cache_miss ||
                       work == Work::two_pass_cached || work == Work::single_pass_hold ||
                       work == Work::two_pass_hold;
  if (work == Work::single_pass_hold || work == Work::two_pass_hold)
    fo.scene_cache.hold_frames = int(state.range(0));
  std::int64_t hits = 0, misses = 0;
  const double pixels = double(projector.camera.width) * projector.camera.height;
  fo.form = two_pass ? Form::two_pass : Form::single_pass;
  fo.warp_screen_only = work != Work::two_pass_full_warp;
  if (work == Work::two_pass_half_eye) fo.eye_texture_size = view->suggested_texture_size() / 2;
  fo.masks_first = work != Work::single_pass_pipelined_outline_last;
  if (work == Work::single_pass_bilinear)
    fo.renderer.texture_filter = scene_render::RendererOptions::TextureFilter::bilinear;
  auto fr = FrameRenderer::create(*view, fo);
  if (!fr) {
    state.SkipWithError(fr.error().message.c_str());
    return;
  }
  for (const auto& [p, a] : f.cache.all()) (void)fr->renderer().upload(*a);
  auto target = scene_render::RenderTarget::create(1920, 1080);
  scene_render::View plain;
  plain.cam_from_world = scene::look_at(kEye, {0, 1.25, -2});
  plain.clip_from_cam = scene::perspective(70 * std::numbers::pi / 180, 1920.0 / 1080, 0.05, 100);
  Readback rb;
  std::vector<projector::ActorMesh> masks(1);
  std::int64_t frame = 0;
  std::uint64_t blackout = 0;
  GLsync previous = nullptr;  // pipelined: the fence after the previous frame
  for (auto _ : state) {
    (void)f.scene.apply({frame++, scene::Tick{}});  // the flyer moves every frame
    if (work == Work::grow_mask) {
      masks[0] = projector::grow_mesh(f.actor, 0.02).value();
      benchmark::DoNotOptimize(masks[0].vertices.data());
      continue;
    }
    if (work == Work::clear) {
      target->bind();
      glClearColor(0, 0, 0, 1);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    } else if (work == Work::plain) {
      target->bind();
      fr->renderer().draw(f.scene, plain);
    } else if (layered) {
      masks[0] = projector::grow_mesh(f.actor, 0.02).value();
      const projector::SceneLayers layers = projector::split_scene(f.scene, f.moving);
      // Miss: the eye on a 2 cm circle, 6 mm further each frame (10x the bound).
      const double turn = 0.3 * double(frame);
      const bool walking = work == Work::single_pass_cache_miss ||
                           work == Work::single_pass_hold || work == Work::two_pass_hold;
      const Eigen::Vector3d eye =
          walking
              ? Eigen::Vector3d(kEye + 0.02 * Eigen::Vector3d(std::cos(turn), std::sin(turn), 0))
              : kEye;
      auto info = fr->render(LayeredScene{layers.still, layers.still_version, &layers.moving},
                             eye, masks);
      if (!info) state.SkipWithError("render failed");
      (info && info->from_cache ? hits : misses) += 1;
    } else if (work == Work::late_latch) {
      state.PauseTiming();  // the scene drawn ahead, off the mesh's path
      if (!fr->prepare(f.scene, kEye)) state.SkipWithError("prepare failed");
      glFinish();
      state.ResumeTiming();
      masks[0] = projector::grow_mesh(f.actor, 0.02).value();
      fr->draw_masks(masks);
    } else {
      if (work == Work::single_pass_pipelined_no_mask)
        masks.clear();
      else if (work == Work::single_pass_pipelined_outline ||
               work == Work::single_pass_pipelined_outline_last)
        masks[0] = projector::grow_outline(f.actor, 0.02, projector.camera).value();
      else
        masks[0] = projector::grow_mesh(f.actor, 0.02).value();  // per frame, as the node
      if (!fr->render(f.scene, kEye, masks)) state.SkipWithError("render failed");
    }
    if (work == Work::single_pass_readback || work == Work::late_latch) {
      glFinish();
      fr->read(rb);
      blackout = rb.blackout.area();
    } else if (work == Work::single_pass_pipelined || work == Work::single_pass_pipelined_no_mask ||
               work == Work::single_pass_pipelined_outline ||
               work == Work::single_pass_pipelined_outline_last) {
      // One frame in flight: llvmpipe's threads shade frame N while this thread bins frame N+1;
      // wait for frame N-1 (its fence) before queueing more.
      const GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
      glFlush();
      if (previous) {
        glClientWaitSync(previous, GL_SYNC_FLUSH_COMMANDS_BIT, GL_TIMEOUT_IGNORED);
        glDeleteSync(previous);
      }
      previous = fence;
    } else {
      glFinish();
    }
  }
  if (previous) {
    glClientWaitSync(previous, GL_SYNC_FLUSH_COMMANDS_BIT, GL_TIMEOUT_IGNORED);
    glDeleteSync(previous);
  }
  if (work == Work::plain) {
    target->bind();
    state.counters["shaded_per_px"] =
        shaded_per_pixel(pixels, [&] { fr->renderer().draw(f.scene, plain); });
  } else if (work != Work::clear && work != Work::grow_mask) {
    state.counters["shaded_per_px"] =
        shaded_per_pixel(pixels, [&] { (void)fr->render(f.scene, kEye, masks); });
  }
  if (work != Work::clear && work != Work::grow_mask)
    state.counters["triangles"] = double(fr->renderer().triangles_last_frame());
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  if (work == Work::single_pass_readback || work == Work::late_latch)
    state.counters["blackout_px"] = double(blackout);
  if (layered)
    state.counters["from_cache"] = double(hits) / double(std::max<std::int64_t>(1, hits + misses));
  state.counters["pixels"] = pixels;
  state.SetLabel(f.context.renderer());
}

}  // namespace

namespace {
void BM_Clear(benchmark::State& s) { run(s, Work::clear); }
void BM_GrowMask(benchmark::State& s) { run(s, Work::grow_mask); }
void BM_PlainScene(benchmark::State& s) { run(s, Work::plain); }
void BM_SinglePass(benchmark::State& s) { run(s, Work::single_pass); }
void BM_SinglePassBilinear(benchmark::State& s) { run(s, Work::single_pass_bilinear); }
void BM_SinglePassPipelined(benchmark::State& s) { run(s, Work::single_pass_pipelined); }
void BM_SinglePassPipelinedNoMask(benchmark::State& s) {
  run(s, Work::single_pass_pipelined_no_mask);
}
void BM_SinglePassPipelinedOutline(benchmark::State& s) {
  run(s, Work::single_pass_pipelined_outline);
}
void BM_SinglePassPipelinedOutlineLast(benchmark::State& s) {
  run(s, Work::single_pass_pipelined_outline_last);
}
void BM_TwoPass(benchmark::State& s) { run(s, Work::two_pass); }
void BM_TwoPassFullWarp(benchmark::State& s) { run(s, Work::two_pass_full_warp); }
void BM_SinglePassReadback(benchmark::State& s) { run(s, Work::single_pass_readback); }
void BM_SinglePassCached(benchmark::State& s) { run(s, Work::single_pass_cached); }
void BM_SinglePassCacheMiss(benchmark::State& s) { run(s, Work::single_pass_cache_miss); }
void BM_TwoPassCached(benchmark::State& s) { run(s, Work::two_pass_cached); }
void BM_SinglePass_720p(benchmark::State& s) { run(s, Work::single_pass, true); }
void BM_SinglePassReadback_720p(benchmark::State& s) {
  run(s, Work::single_pass_readback, true);
}
void BM_LateLatch_720p(benchmark::State& s) { run(s, Work::late_latch, true); }
void BM_SinglePassCached_720p(benchmark::State& s) { run(s, Work::single_pass_cached, true); }
void BM_TwoPass_720p(benchmark::State& s) { run(s, Work::two_pass, true); }
void BM_TwoPassHalfEye_720p(benchmark::State& s) { run(s, Work::two_pass_half_eye, true); }
void BM_TwoPassHalfEye(benchmark::State& s) { run(s, Work::two_pass_half_eye); }
void BM_SinglePassCacheMiss_720p(benchmark::State& s) {
  run(s, Work::single_pass_cache_miss, true);
}
// scene_cache.hold_frames = arg with the cache miss's walking eye: the static layer drawn every
// arg + 1 frames and held in between (arg 0 = the cache miss, the baseline in the same run).
void BM_SinglePassHold(benchmark::State& s) { run(s, Work::single_pass_hold); }
void BM_TwoPassHold(benchmark::State& s) { run(s, Work::two_pass_hold); }
void BM_SinglePassHold_720p(benchmark::State& s) { run(s, Work::single_pass_hold, true); }
// The hull's arm-swing mesh (testing/hull_meshes.h), made once.
const projector::ActorMesh& arm_swing_hull() {
  static const projector::ActorMesh hull =
      projector::testing::hull_meshes(sim::Motion::arm_swing, 60, 1).front();
  return hull;
}

// A frame renderer for `view` with the default scene's assets uploaded; nullopt (the benchmark
// skipped with the error) when it cannot be made.
std::optional<FrameRenderer> renderer_720p(benchmark::State& state, Fixture& f,
                                           const projector::ProjectorView& view) {
  auto fr = FrameRenderer::create(view, {});
  if (!fr) {
    state.SkipWithError(fr.error().message.c_str());
    return std::nullopt;
  }
  for (const auto& [p, a] : f.cache.all()) (void)fr->renderer().upload(*a);
  return std::move(*fr);
}

// The mask of a live-like hull mesh (the arm swing's, testing/hull_meshes.h, ~38k triangles)
// simplified by GrowOptions max_triangles (arg 0) and cluster_factor (arg 1), as the late-latched
// node draws it per frame at 720p: grown by arg 2 mm (+ the simplification's error; 200: the
// margin's cap, where a starved projector's margin sits) — arg 3: 0 the vertex push, 1 the
// outline (GrowOptions::projector, the node's default mask_growth) from the whole mesh (its
// default: args 0 and 1 then do nothing), 2 the outline from the simplified mesh
// (GrowOptions::simplify_outline, the baseline) —, drawn over the
// scene prepared ahead (outside the timing), finished and read back. Counters: triangles drawn,
// the simplification's error (added to the margin) and the pixels blacked out.
void BM_HullMask_720p(benchmark::State& state) {
  Fixture& f = fixture();
  const projector::ActorMesh& hull = arm_swing_hull();
  auto view = projector::ProjectorView::create(at_720p(f.projector));
  auto fr = renderer_720p(state, f, *view);
  if (!fr) return;
  projector::GrowOptions o;
  o.max_triangles = std::size_t(state.range(0));
  o.cluster_factor = std::size_t(state.range(1));
  if (state.range(3)) o.projector = view->camera();  // the outline form
  o.simplify_outline = state.range(3) == 2;
  const projector::MaskBase base = projector::simplify_for_mask(hull, o).value();
  Readback rb;
  std::vector<projector::ActorMesh> masks(1);
  for (auto _ : state) {
    state.PauseTiming();
    if (!fr->prepare(f.scene, kEye)) state.SkipWithError("prepare failed");
    glFinish();
    state.ResumeTiming();
    masks[0] = projector::grow_mask(base, 1e-3 * double(state.range(2)), o).value();
    fr->draw_masks(masks);
    glFinish();
    fr->read(rb);
  }
  state.counters["triangles_drawn"] = double(base.mesh.triangles.size());
  state.counters["error_mm"] = base.error_m * 1e3;
  state.counters["blackout_px"] = double(rb.blackout.area());
}

// The frame the node renders by default (scene_thread: the scene drawn by another thread into an
// image): the newest scene image loaded, the hull's mask (the arm swing's whole mesh, the outline
// form) grown by arg 0 mm and drawn over it, finished — what a new mesh waits for at 1280x720.
// Arg 1: 1 the outline's pixel rectangles cleared (ActorMesh::image_rects: the node's way), 0
// its quads rasterised with the renderer's once-per-pixel depth pass (the baseline, before).
// Counters (ms per frame, wall): grow_ms (grow_mask), load_ms (load_image), draw_finish_ms
// (draw_masks + finish); blackout_px of the last frame (read back outside the timing).
void BM_SceneImageFrame_720p(benchmark::State& state) {
  Fixture& f = fixture();
  const projector::ActorMesh& hull = arm_swing_hull();
  auto view = projector::ProjectorView::create(at_720p(f.projector));
  auto fr = renderer_720p(state, f, *view);
  if (!fr) return;
  if (!fr->render(f.scene, kEye, {})) state.SkipWithError("render failed");
  fr->finish();
  std::vector<std::uint8_t> image;
  fr->read_image(image);
  projector::GrowOptions o;
  o.projector = view->camera();
  const projector::MaskBase base = projector::simplify_for_mask(hull, o).value();
  std::vector<projector::ActorMesh> masks(1);
  using Clock = std::chrono::steady_clock;
  double grow = 0, load = 0, draw = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    masks[0] = projector::grow_mask(base, 1e-3 * double(state.range(0)), o).value();
    if (state.range(1) == 0) masks[0].image_rects.reset();  // the baseline: quads
    const auto t1 = Clock::now();
    fr->load_image(image);
    const auto t2 = Clock::now();
    fr->draw_masks(masks);
    fr->finish();
    const auto t3 = Clock::now();
    grow += std::chrono::duration<double, std::milli>(t1 - t0).count();
    load += std::chrono::duration<double, std::milli>(t2 - t1).count();
    draw += std::chrono::duration<double, std::milli>(t3 - t2).count();
  }
  const double n = double(std::max<benchmark::IterationCount>(state.iterations(), 1));
  state.counters["grow_ms"] = grow / n;
  state.counters["load_ms"] = load / n;
  state.counters["draw_finish_ms"] = draw / n;
  Readback rb;
  fr->read(rb);
  state.counters["blackout_px"] = double(rb.blackout.area());
}
BENCHMARK(BM_SceneImageFrame_720p)->Args({30, 0})->Args({30, 1})->Args({130, 0})->Args({130, 1})->Args({200, 0})->Args({200, 1})->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime()->MeasureProcessCPUTime();

// The blackout runs of a read-back 1280x720 frame (blackout_of; the node does this per frame):
// an elliptical mask of ~200k pixels (the demo's at the margin's cap) over a lit frame.
void BM_BlackoutRuns_720p(benchmark::State& state) {
  const int w = 1280, h = 720;
  std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4, 200);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = (x - 640) / 220.0, v = (y - 360) / 300.0;
      if (u * u + v * v <= 1) rgba[(std::size_t(y) * w + x) * 4 + 3] = 0;
    }
  std::size_t area = 0;
  for (auto _ : state) area = blackout_of(rgba, w, h).area();
  state.counters["blackout_px"] = double(area);
}
BENCHMARK(BM_BlackoutRuns_720p)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// The 160x90 thumbnail of a read-back 1280x720 frame: the box average (box_thumbnail, what read()
// uses) against OpenCV's area resize, flip and colour conversion (the baseline, before).
void BM_Thumbnail_720p(benchmark::State& state) {
  const int w = 1280, h = 720;
  std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = std::uint8_t(i * 7 + i / 5120);
  std::vector<std::uint8_t> out;
  for (auto _ : state) {
    if (state.range(0) == 1) {
      box_thumbnail(rgba, w, h, 160, 90, out);
    } else {
      const cv::Mat full(h, w, CV_8UC4, rgba.data());
      cv::Mat small, rgb;
      cv::resize(full, small, cv::Size(160, 90), 0, 0, cv::INTER_AREA);
      cv::flip(small, small, 0);
      cv::cvtColor(small, rgb, cv::COLOR_RGBA2RGB);
      out.assign(rgb.data, rgb.data + rgb.total() * 3);
    }
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_Thumbnail_720p)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(1.0)->MeasureProcessCPUTime();

#define OPTS ->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(2.0)
BENCHMARK(BM_Clear) OPTS;
BENCHMARK(BM_GrowMask) OPTS;
BENCHMARK(BM_PlainScene) OPTS;
BENCHMARK(BM_SinglePass) OPTS;
BENCHMARK(BM_SinglePassBilinear) OPTS;
BENCHMARK(BM_SinglePassPipelined) OPTS;
BENCHMARK(BM_SinglePassPipelinedNoMask) OPTS;
BENCHMARK(BM_SinglePassPipelinedOutline) OPTS;
BENCHMARK(BM_SinglePassPipelinedOutlineLast) OPTS;
BENCHMARK(BM_TwoPass) OPTS;
BENCHMARK(BM_TwoPassFullWarp) OPTS;
BENCHMARK(BM_SinglePassReadback) OPTS;
BENCHMARK(BM_SinglePassCached) OPTS;
BENCHMARK(BM_SinglePassCacheMiss) OPTS;
BENCHMARK(BM_TwoPassCached) OPTS;
BENCHMARK(BM_SinglePass_720p) OPTS;
BENCHMARK(BM_SinglePassReadback_720p) OPTS;
BENCHMARK(BM_LateLatch_720p) OPTS;
BENCHMARK(BM_SinglePassCached_720p) OPTS;
BENCHMARK(BM_SinglePassCacheMiss_720p) OPTS;
BENCHMARK(BM_TwoPass_720p) OPTS;
BENCHMARK(BM_TwoPassHalfEye_720p) OPTS;
BENCHMARK(BM_TwoPassHalfEye) OPTS;
BENCHMARK(BM_SinglePassHold) OPTS->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_TwoPassHold) OPTS->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_SinglePassHold_720p) OPTS->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_HullMask_720p)
    ->Args({3000, 4, 30, 0})
    ->Args({12000, 1, 30, 0})
    ->Args({8000, 1, 30, 0})
    ->Args({3000, 4, 100, 0})
    ->Args({3000, 4, 200, 0})
    ->Args({3000, 4, 30, 2})
    ->Args({3000, 4, 100, 2})
    ->Args({3000, 4, 200, 2})
    ->Args({3000, 4, 30, 1})
    ->Args({3000, 4, 100, 1})
    ->Args({3000, 4, 200, 1}) OPTS;
}  // namespace

BENCHMARK_MAIN();

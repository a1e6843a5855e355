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
// cases). Counters: shaded_per_px (fragments past the depth test in one frame / pixels: the
// overdraw llvmpipe shades; 1.0 = once per pixel), triangles (submitted in the last frame).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <benchmark/benchmark.h>

#include <numbers>

#include "projector/mask_geometry.h"
#include "projector_render/frame_renderer.h"
#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "sim/actor.h"
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
    return new Fixture{std::move(*ctx), std::move(cache), std::move(*s),
                       projector::testing::studio_projectors()[0], std::move(actor)};
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
  two_pass,
  two_pass_full_warp,
  single_pass_readback
};

// Fragments that passed the depth test (llvmpipe shades those: early depth test) in one frame,
// over the frame's pixel count: 1.0 = every pixel shaded once.
template <class Draw>
double shaded_per_pixel(Draw&& draw) {
  GLuint query = 0;
  glGenQueries(1, &query);
  glBeginQuery(GL_SAMPLES_PASSED, query);
  draw();
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint64 samples = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &samples);
  glDeleteQueries(1, &query);
  return static_cast<double>(samples) / (1920.0 * 1080.0);
}

void run(benchmark::State& state, Work work) {
  Fixture& f = fixture();
  auto view = projector::ProjectorView::create(f.projector);
  FrameRendererOptions fo;
  const bool two_pass = work == Work::two_pass || work == Work::two_pass_full_warp;
  fo.form = two_pass ? Form::two_pass : Form::single_pass;
  fo.warp_screen_only = work != Work::two_pass_full_warp;
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
    } else {
      masks[0] = projector::grow_mesh(f.actor, 0.02).value();  // per frame, as the node
      if (!fr->render(f.scene, kEye, masks)) state.SkipWithError("render failed");
    }
    if (work == Work::single_pass_readback) {
      fr->read(rb);
      blackout = rb.blackout.area();
    } else if (work == Work::single_pass_pipelined) {
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
        shaded_per_pixel([&] { fr->renderer().draw(f.scene, plain); });
  } else if (work != Work::clear && work != Work::grow_mask) {
    state.counters["shaded_per_px"] =
        shaded_per_pixel([&] { (void)fr->render(f.scene, kEye, masks); });
  }
  if (work != Work::clear && work != Work::grow_mask)
    state.counters["triangles"] = double(fr->renderer().triangles_last_frame());
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  if (work == Work::single_pass_readback) state.counters["blackout_px"] = double(blackout);
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
void BM_TwoPass(benchmark::State& s) { run(s, Work::two_pass); }
void BM_TwoPassFullWarp(benchmark::State& s) { run(s, Work::two_pass_full_warp); }
void BM_SinglePassReadback(benchmark::State& s) { run(s, Work::single_pass_readback); }
#define OPTS ->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(2.0)
BENCHMARK(BM_Clear) OPTS;
BENCHMARK(BM_GrowMask) OPTS;
BENCHMARK(BM_PlainScene) OPTS;
BENCHMARK(BM_SinglePass) OPTS;
BENCHMARK(BM_SinglePassBilinear) OPTS;
BENCHMARK(BM_SinglePassPipelined) OPTS;
BENCHMARK(BM_TwoPass) OPTS;
BENCHMARK(BM_TwoPassFullWarp) OPTS;
BENCHMARK(BM_SinglePassReadback) OPTS;
}  // namespace

BENCHMARK_MAIN();

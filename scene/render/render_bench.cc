// Renderer frame time on Mesa llvmpipe (EGL surfaceless) with the default demo scene at 1280x720
// and 1920x1080, against baselines in the same run: clear only, clear + read-back, and the
// reference shading (Blinn-Phong per fragment) beside the fast one (per vertex, the default), and
// the fast one drawing every full mesh in scene order (cull_and_sort off, lod_pixel_error 0: the
// renderer before those levers).
#include <benchmark/benchmark.h>

#include <numbers>

#include "gl.h"
#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "scene_render/renderer.h"

using namespace studio;
using namespace studio::scene_render;

namespace {

struct Fixture {
  HeadlessContext context;
  scene_assets::AssetCache cache;
  scene::Scene scene;
  Renderer renderer;
  Renderer reference;
  Renderer every;  // fast shading, full meshes, no culling, scene order (the renderer before)
  scene_assets::ViewSpec view;
};

Fixture& fixture() {
  static Fixture* f = [] {
    auto ctx = HeadlessContext::create();
    if (!ctx) throw std::runtime_error(ctx.error().message);
    auto d = scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml");
    if (!d) throw std::runtime_error(d.error().message);
    scene_assets::AssetCache cache;
    auto s = scene_assets::build_scene(*d, cache);
    if (!s) throw std::runtime_error(s.error().message);
    RendererOptions ro;
    ro.shading = RendererOptions::Shading::fast;
    auto r = Renderer::create(ro);
    if (!r) throw std::runtime_error(r.error().message);
    ro.shading = RendererOptions::Shading::reference;
    ro.lod_pixel_error = 0;  // the exact path: full meshes
    auto ref = Renderer::create(ro);
    if (!ref) throw std::runtime_error(ref.error().message);
    ro.shading = RendererOptions::Shading::fast;
    ro.cull_and_sort = false;
    auto every = Renderer::create(ro);
    if (!every) throw std::runtime_error(every.error().message);
    for (const auto& [p, a] : cache.all()) {
      (void)r->upload(*a);
      (void)ref->upload(*a);
      (void)every->upload(*a);
    }
    return new Fixture{std::move(*ctx), std::move(cache),  std::move(*s), std::move(*r),
                       std::move(*ref), std::move(*every), *d->view};
  }();
  return *f;
}

View view_for(const scene_assets::ViewSpec& v, int w, int h) {
  View out;
  out.cam_from_world = scene::look_at({v.eye[0], v.eye[1], v.eye[2]}, {v.at[0], v.at[1], v.at[2]});
  out.clip_from_cam =
      scene::perspective(v.fov_deg * std::numbers::pi / 180, double(w) / h, 0.05, 200);
  return out;
}

enum class Work { clear, clear_readback, draw, draw_readback, draw_reference, draw_every };

void run(benchmark::State& state, Work work) {
  Fixture& f = fixture();
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  auto target = RenderTarget::create(w, h);
  if (!target) {
    state.SkipWithError(target.error().message.c_str());
    return;
  }
  const View view = view_for(f.view, w, h);
  std::vector<std::uint8_t> pixels;
  std::int64_t frame = 0;
  for (auto _ : state) {
    target->bind();
    if (work != Work::clear && work != Work::clear_readback) {
      (void)f.scene.apply({frame++, scene::Tick{}});  // the flyer moves every frame
      (work == Work::draw_reference ? f.reference
       : work == Work::draw_every   ? f.every
                                    : f.renderer)
          .draw(f.scene, view);
    } else {
      glClearColor(0, 0, 0, 1);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    if (work == Work::clear_readback || work == Work::draw_readback)
      target->read_rgba(pixels);
    else
      glFinish();
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(f.context.renderer());
}

void BM_Clear(benchmark::State& s) { run(s, Work::clear); }
void BM_ClearReadback(benchmark::State& s) { run(s, Work::clear_readback); }
void BM_DrawScene(benchmark::State& s) { run(s, Work::draw); }
void BM_DrawSceneReadback(benchmark::State& s) { run(s, Work::draw_readback); }
void BM_DrawSceneReference(benchmark::State& s) { run(s, Work::draw_reference); }
void BM_DrawSceneEvery(benchmark::State& s) { run(s, Work::draw_every); }

#define SIZES                         \
  ->Args({1280, 720})                 \
      ->Args({1920, 1080})            \
      ->Unit(benchmark::kMillisecond) \
      ->UseRealTime()                 \
      ->MeasureProcessCPUTime()
BENCHMARK(BM_Clear) SIZES;
BENCHMARK(BM_ClearReadback) SIZES;
BENCHMARK(BM_DrawScene) SIZES;
BENCHMARK(BM_DrawSceneReadback) SIZES;
BENCHMARK(BM_DrawSceneReference) SIZES;
BENCHMARK(BM_DrawSceneEvery) SIZES;

}  // namespace

BENCHMARK_MAIN();

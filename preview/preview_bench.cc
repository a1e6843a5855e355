// The director's preview on Mesa llvmpipe (EGL surfaceless), 1280x720, the default museum scene
// plus the live actor: frame time of the scene alone (baseline, the renderer's own cost), the
// actor textured from the nearest camera (the paper's), and the blend of three cameras with
// visibility; and per new mesh, the upload of the mesh, the camera images and their visibility
// depth maps. Samples: the simulated studio's actor (its tessellated true surface, ~the hull
// mesh's size) and the five ring cameras' images of the same frame (352x288 and 704x576), made
// once before timing. Each timed frame ends with glFinish (llvmpipe renders on the CPU).
// BM_PreviewOverlays: the nearest-camera frame plus every overlay (the five cameras' frusta, a
// projector's frustum and its screen showing a 160x90 thumbnail, a head marker); its baseline
// is BM_PreviewFrame/cameras:1/image_w:352 of the same run.
// masks:5: the blend also carves against the five cameras' actor masks (the node's carve_masks;
// ActorTexturer::set_carving_masks); per new mesh that adds the masks' upload.
// BM_PreviewColourBalance: per new mesh, the cameras' colour balance pooled and solved
// (preview/rig_balance.h; CPU, no GL).
#include <benchmark/benchmark.h>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

#include <numbers>

#include "actor_texturer.h"
#include "overlay_renderer.h"
#include "preview/rig_balance.h"
#include "scene/view.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "scene_render/egl_context.h"
#include "scene_render/render_target.h"
#include "scene_render/renderer.h"
#include "sim/cameras.h"
#include "sim/studio.h"

using namespace studio;

namespace {

constexpr int kW = 1280, kH = 720;

struct Samples {
  std::vector<Camera> cameras;
  std::vector<Image<Rgb8>> images;
  std::vector<Mask> masks;
  scene::ActorMesh mesh;
};

struct Fixture {
  scene_render::HeadlessContext context;
  scene::Scene scene;
  scene_render::Renderer renderer;
  preview::ActorTexturer texturer;
  scene_render::RenderTarget target;
  std::map<int, Samples> samples;  // by camera image width
};

Samples make_samples(int width, int count = 5) {
  sim::RingOptions ring;
  ring.count = count;
  ring.width = width;
  ring.height = width * 576 / 704;
  ring.focal_px *= width / 704.0;
  Samples s;
  s.cameras = sim::ring_cameras(ring);
  sim::StudioOptions o;
  o.threads = 2;
  auto studio = sim::SimulatedStudio::create(s.cameras, o).value();
  const sim::FrameTruth truth = studio.render_all(100, &s.images, &s.masks);
  const sim::TriangleMesh m = truth.body.mesh(24);
  s.mesh.actor_id = "actor0";
  s.mesh.vertices = m.vertices;
  for (const auto& t : m.triangles) s.mesh.triangles.push_back(t);
  s.mesh.compute_normals();
  return s;
}

Fixture& fixture() {
  static Fixture* f = [] {
    auto ctx = scene_render::HeadlessContext::create();
    if (!ctx) throw std::runtime_error(ctx.error().message);
    auto d = scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml");
    if (!d) throw std::runtime_error(d.error().message);
    scene_assets::AssetCache cache;
    auto s = scene_assets::build_scene(*d, cache);
    if (!s) throw std::runtime_error(s.error().message);
    auto r = scene_render::Renderer::create().value();
    for (const auto& [p, a] : cache.all()) (void)r.upload(*a);
    auto t = preview::ActorTexturer::create().value();
    auto target = scene_render::RenderTarget::create(kW, kH).value();
    auto* out = new Fixture{std::move(*ctx), std::move(*s),     std::move(r),
                            std::move(t),    std::move(target), {}};
    out->samples[352] = make_samples(352);
    out->samples[704] = make_samples(704);
    return out;
  }();
  return *f;
}

// The view between cam0 and cam1, 4.5 m out.
const Eigen::Vector3d kEye(1.6, 1.7, 4.2);
constexpr double kThreshold = 1.6;  // the blend's threshold angle (radians), ~ the 4th camera's
scene_render::View view() {
  scene_render::View v;
  v.cam_from_world = scene::look_at(kEye, {0, 1.0, 0});
  v.clip_from_cam = scene::perspective(50 * std::numbers::pi / 180, double(kW) / kH, 0.05, 200);
  return v;
}

void upload(Fixture& f, const Samples& s, int cameras, int masks) {
  (void)f.texturer.set_mesh(s.mesh);
  // cam0, cam1, cam4: the three nearest of the view (camera_select.h's choice for it).
  const int order[3] = {0, 1, 4};
  for (int i = 0; i < cameras; ++i)
    (void)f.texturer.set_camera(i, s.cameras[order[i]],
                                reinterpret_cast<const uint8_t*>(s.images[order[i]].data()));
  std::vector<preview::ActorTexturer::CarvingMask> carving;
  for (int i = 0; i < masks; ++i) carving.push_back({&s.cameras[i], s.masks[i].data()});
  (void)f.texturer.set_carving_masks(carving);
}

// cameras 0: the scene alone; 1: nearest; 3: the blend.
void BM_PreviewFrame(benchmark::State& state) {
  Fixture& f = fixture();
  const int cameras = int(state.range(0));
  const Samples& s = f.samples.at(int(state.range(1)));
  f.target.bind();
  upload(f, s, std::max(cameras, 1), int(state.range(2)));
  const scene_render::View v = view();
  std::array<float, 3> w{};
  if (cameras == 1) w = {1, 0, 0};
  if (cameras == 3) w = {0.5f, 0.3f, 0.2f};
  for (auto _ : state) {
    f.target.bind();
    f.renderer.draw(f.scene, v);
    if (cameras > 0)
      f.texturer.draw({v.clip_from_cam * v.cam_from_world, kEye, kW, kH},
                      cameras == 1 ? preview::TextureMode::nearest : preview::TextureMode::blend, w,
                      kThreshold);
    glFinish();
  }
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(s.mesh.triangles.size());
}
BENCHMARK(BM_PreviewFrame)
    ->ArgNames({"cameras", "image_w", "masks"})
    ->Args({0, 352, 0})
    ->Args({1, 352, 0})
    ->Args({3, 352, 0})
    ->Args({3, 352, 5})
    ->Args({1, 704, 0})
    ->Args({3, 704, 0})
    ->Args({3, 704, 5})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Per new mesh: mesh upload, camera images and their depth maps (1 or 3 cameras).
void BM_PreviewNewMesh(benchmark::State& state) {
  Fixture& f = fixture();
  const int cameras = int(state.range(0));
  const Samples& s = f.samples.at(int(state.range(1)));
  for (auto _ : state) {
    f.target.bind();
    upload(f, s, cameras, int(state.range(2)));
    glFinish();
  }
}
BENCHMARK(BM_PreviewNewMesh)
    ->ArgNames({"cameras", "image_w", "masks"})
    ->Args({1, 352, 0})
    ->Args({3, 352, 0})
    ->Args({3, 352, 5})
    ->Args({1, 704, 0})
    ->Args({3, 704, 0})
    ->Args({3, 704, 5})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Per new mesh with the colour balance on (preview/rig_balance.h): one frame pooled from the three
// texturing cameras' images and masks, then solved; its baseline is BM_PreviewNewMesh/cameras:3
// of the same image width (the upload every new mesh pays).
void BM_PreviewColourBalance(benchmark::State& state) {
  Fixture& f = fixture();
  const Samples& s = f.samples.at(int(state.range(0)));
  std::map<std::string, Camera> rig;
  for (const Camera& c : s.cameras) rig[c.id] = c;
  std::vector<RunMask> runs;
  for (const Mask& m : s.masks) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<preview::BalanceView> views;
  for (int c : {0, 1, 4}) views.push_back({s.cameras[c].id, s.images[c].view(), &runs[c]});
  preview::RigBalance balance;
  for (auto _ : state)
    if (auto ok = balance.add(rig, s.mesh, views); !ok)
      state.SkipWithError(ok.error().message.c_str());
  const offline::ColourBalance& b = balance.balance();
  state.counters["pairs"] = b.pairs;
  // Mesh vertices two of the cameras see, per frame.
  state.counters["points"] = b.frames ? double(b.points) / b.frames : 0;
}
BENCHMARK(BM_PreviewColourBalance)
    ->ArgNames({"image_w"})
    ->Arg(352)
    ->Arg(704)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A rig sample (node/view_pipeline.h, balance_rig_every): one frame pooled from every camera of
// a 9-camera rig (8 ring + overhead, as the studio tests'), against the view's three (views: 3)
// on the same rig and frame.
void BM_PreviewRigSample(benchmark::State& state) {
  static const std::map<int, Samples> rigs{{352, make_samples(352, 9)},
                                           {704, make_samples(704, 9)}};
  const Samples& s = rigs.at(int(state.range(0)));
  const int count = int(state.range(1));
  std::map<std::string, Camera> rig;
  for (const Camera& c : s.cameras) rig[c.id] = c;
  std::vector<RunMask> runs;
  for (const Mask& m : s.masks) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<preview::BalanceView> views;
  for (int c = 0; c < int(s.cameras.size()); ++c)
    if (count > 3 || c == 0 || c == 1 || c == 7)
      views.push_back(
          {s.cameras[std::size_t(c)].id, s.images[std::size_t(c)].view(), &runs[std::size_t(c)]});
  preview::RigBalance balance;
  for (auto _ : state)
    if (auto ok = balance.add(rig, s.mesh, views); !ok)
      state.SkipWithError(ok.error().message.c_str());
  state.counters["pairs"] = balance.balance().pairs;
}
BENCHMARK(BM_PreviewRigSample)
    ->ArgNames({"image_w", "views"})
    ->Args({352, 3})
    ->Args({352, 9})
    ->Args({704, 3})
    ->Args({704, 9})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The nearest-camera frame with every overlay on (preview/overlays.h).
void BM_PreviewOverlays(benchmark::State& state) {
  Fixture& f = fixture();
  const Samples& s = f.samples.at(352);
  f.target.bind();
  upload(f, s, 1, 0);
  auto overlay = preview::OverlayRenderer::create().value();
  std::vector<uint8_t> thumb(160 * 90 * 3);
  for (std::size_t i = 0; i < thumb.size(); ++i) thumb[i] = uint8_t(i * 7);
  (void)overlay.set_thumbnail("proj0", 160, 90, thumb.data());
  Projector p;
  p.camera = s.cameras[0];
  p.camera.id = "proj0";
  p.camera.width = 1280;
  p.camera.height = 720;
  p.camera.intrinsics.cx = 639.5;
  p.camera.intrinsics.cy = 359.5;
  p.screen = {Eigen::Vector3d(-2, 0, -2.5), Eigen::Vector3d(2, 0, -2.5),
              Eigen::Vector3d(2, 2.5, -2.5), Eigen::Vector3d(-2, 2.5, -2.5)};
  const auto geometry =
      preview::build_overlays({}, s.cameras, {p}, {{"actor0", {0, 1.65, 0}, {0.3, 0, 0}, 1}});
  const scene_render::View v = view();
  const Eigen::Matrix4d clip = v.clip_from_cam * v.cam_from_world;
  const std::array<float, 3> w{1, 0, 0};
  for (auto _ : state) {
    f.target.bind();
    f.renderer.draw(f.scene, v);
    f.texturer.draw({clip, kEye, kW, kH}, preview::TextureMode::nearest, w, kThreshold);
    overlay.draw(geometry, clip, kW, kH);
    glFinish();
  }
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["lines"] = double(geometry.lines.size());
}
BENCHMARK(BM_PreviewOverlays)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

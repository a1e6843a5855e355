#include "view_pipeline.h"

#include <filesystem>
#include <mutex>
#include <numbers>
#include <set>

#include "actor_texturer.h"
#include "balance_worker.h"
#include "core/log.h"
#include "overlay_renderer.h"
#include "scene/view.h"
#include "scene_assets/asset.h"
#include "scene_render/renderer.h"

namespace studio::preview {
namespace {

struct Choice {
  std::vector<std::string> cameras;
  std::vector<float> weights;
  double threshold = 0;
};

// The texturing cameras for a mesh centred at `centre` seen from `eye` (camera_select.h).
Choice choose(const std::map<std::string, Camera>& cams, bool blend, BlendOptions bo,
              const Eigen::Vector3d& eye, const Eigen::Vector3d& centre) {
  std::vector<StudioCameraPose> poses;
  std::vector<std::string> ids;
  for (const auto& [id, c] : cams) {
    poses.push_back({id, c.centre_in_world()});
    ids.push_back(id);
  }
  bo.cameras = std::min(bo.cameras, ActorTexturer::kMaxCameras);
  const auto chosen =
      blend ? preview::blend(poses, eye, centre, bo) : preview::nearest(poses, eye, centre);
  Choice out;
  out.threshold = preview::blend_threshold(poses, eye, centre, bo);
  for (const auto& w : chosen) {
    out.cameras.push_back(ids[w.index]);
    out.weights.push_back(float(w.weight));
  }
  return out;
}

// What the node's prefetch (on its loop thread) needs of the render thread: the viewpoint of the
// last drawn frame and the texturing mode. Shared, so it outlives the pipeline if a callback runs.
struct PrefetchState {
  std::mutex mutex;
  bool have_eye = false, blend = true;
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  BlendOptions options;
};

}  // namespace

struct ViewPipeline::Impl {
  PreviewNode* node = nullptr;
  PipelineOptions options;
  scene_render::Renderer renderer;
  ActorTexturer texturer;
  OverlayRenderer overlay;
  std::map<std::string, uint64_t> thumbnail_versions;  // uploaded, per projector
  scene::Scene scene;
  uint64_t scene_version = 0;
  std::set<std::string> uploaded, failed;
  std::vector<std::string> problems;
  uint64_t mesh_sequence = 0;
  // The mesh waiting for its images, and what is drawn now.
  std::optional<LiveMesh> pending;
  std::chrono::steady_clock::time_point pending_since;
  std::vector<std::string> pending_cameras;
  std::vector<float> pending_weights;
  double pending_threshold = 0, current_threshold = 0;
  bool have_current = false, current_textured = false;
  FrameReport current;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  PipelineCounts counts;
  std::vector<Camera> carving_cameras;  // the carving masks' cameras and masks (kept: uploaded)
  std::vector<Mask> carving_masks;
  std::size_t carving_count = 0;
  BalanceWorker balance;
  // The rig samples' estimate, on a thread of its own at a lower priority: background work, which
  // must not slow the live balance, the rendering or the capture servers on the same machine.
  BalanceWorker rig_balance{10};
  int64_t pool_from_ns = 0;  // restart_colour_balance(): meshes captured before are not pooled
  uint64_t textured_seen =
      0;  // meshes pool_balance() saw (the first and every balance_every-th pool)
  std::shared_ptr<PrefetchState> prefetch = std::make_shared<PrefetchState>();
  // The rig sample waiting for its images (PipelineOptions::balance_rig_every).
  struct RigSample {
    scene::ActorMesh mesh;
    uint64_t frame = 0;
    std::vector<std::string> cameras;
    std::chrono::steady_clock::time_point since;
  };
  std::optional<RigSample> rig_sample;
  std::chrono::steady_clock::time_point last_rig_sample{};

  Impl(PreviewNode& n, const PipelineOptions& o, scene_render::Renderer r, ActorTexturer t,
       OverlayRenderer ov)
      : node(&n),
        options(o),
        renderer(std::move(r)),
        texturer(std::move(t)),
        overlay(std::move(ov)) {}

  // The overlays from the node's mirror of the wire; new thumbnails uploaded once each.
  void draw_overlays(const Eigen::Matrix4d& clip_from_world, int width, int height) {
    const OverlayOptions& o = options.overlays;
    if (!o.head && !o.camera_frusta && !o.projector_frusta && !o.projector_screens) return;
    const OverlayInputs& in = node->overlays();
    if (o.projector_screens)
      for (const auto& [id, p] : in.projectors()) {
        uint64_t& uploaded = thumbnail_versions[id];
        if (p.thumbnail.empty() || uploaded == p.thumbnail_version) continue;
        uploaded = p.thumbnail_version;
        if (auto ok = overlay.set_thumbnail(id, p.thumb_width, p.thumb_height, p.thumbnail.data());
            !ok)
          STUDIO_LOG(warn, "preview") << ok.error().message;
      }
    std::vector<Camera> cams;
    if (o.camera_frusta)
      for (auto& [id, c] : node->cameras()) cams.push_back(std::move(c));
    const auto geometry =
        build_overlays(o, cams, in.calibrated(), o.head ? in.heads() : std::vector<HeadMarker>{});
    overlay.draw(geometry, clip_from_world, width, height);
  }

  void refresh_scene() {
    auto s = node->scene_after(scene_version);
    if (!s) return;
    scene = std::move(*s);
    for (const auto& [id, n] : scene.nodes()) {
      if (n.kind != scene::NodeKind::model || uploaded.count(n.asset.path) ||
          failed.count(n.asset.path))
        continue;
      std::filesystem::path p = n.asset.path;
      if (p.is_relative() && !options.asset_root.empty()) p = options.asset_root / p;
      auto a = scene_assets::load_asset(p.string());
      if (a) {
        a->path = n.asset.path;  // the renderer matches nodes by the path they name
        if (auto ok = renderer.upload(*a); ok) {
          uploaded.insert(n.asset.path);
          continue;
        }
      }
      failed.insert(n.asset.path);
      problems.push_back(n.asset.path + ": " + (a ? "upload failed" : a.error().message));
      STUDIO_LOG(warn, "preview") << problems.back();
    }
  }

  // Chooses the cameras for a new mesh seen from `eye` and asks for their images.
  void take_new_mesh(const Viewpoint& view) {
    auto m = node->mesh_after(mesh_sequence);
    if (!m) return;
    if (pending) ++counts.skipped;  // superseded before its images came: never drawn
    mesh_sequence = m->sequence;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
    for (const auto& v : m->mesh.vertices) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
    if (!m->mesh.vertices.empty()) centre = 0.5 * (lo + hi);
    start_rig_sample(*m);
    Choice c = choose(node->cameras(), options.blend, options.blend_options, view.eye, centre);
    pending_threshold = c.threshold;
    pending = std::move(*m);
    pending_since = std::chrono::steady_clock::now();
    pending_cameras = std::move(c.cameras);
    pending_weights = std::move(c.weights);
    node->request_images(pending->source_frame, pending_cameras);
  }

  // The blend's carving masks: every calibrated camera's mask of exactly `frame` that arrived,
  // of the first such camera's size (one texture array), at most kMaxMasks; else none.
  void set_carving_masks(const std::map<std::string, Camera>& cams,
                         const std::map<std::string, RunMask>& masks) {
    carving_cameras.clear();
    carving_masks.clear();
    if (options.blend && options.carve_all_masks) {
      for (auto& [id, m] : masks) {
        const auto c = cams.find(id);
        if (c == cams.end() || m.width() != c->second.width || m.height() != c->second.height)
          continue;
        carving_cameras.push_back(c->second);
        carving_masks.push_back(m.to_mask());
      }
      // One size for the texture array: keep the cameras of the first camera's size.
      for (std::size_t i = carving_cameras.size(); i-- > 0;)
        if (carving_cameras[i].width != carving_cameras[0].width ||
            carving_cameras[i].height != carving_cameras[0].height ||
            int(i) >= ActorTexturer::kMaxMasks) {
          carving_cameras.erase(carving_cameras.begin() + i);
          carving_masks.erase(carving_masks.begin() + i);
        }
    }
    std::vector<ActorTexturer::CarvingMask> list;
    for (std::size_t i = 0; i < carving_cameras.size(); ++i)
      list.push_back({&carving_cameras[i], carving_masks[i].data()});
    if (auto ok = texturer.set_carving_masks(list); !ok)
      STUDIO_LOG(warn, "preview") << ok.error().message;
    carving_count = list.size();
  }

  // Hands the pending mesh's texturing images and their masks to the colour balance's worker
  // when the balance is on, the mesh has two or more texturing cameras (nearest mode's one
  // compares nothing) and it is the first such mesh or the balance_every-th since; true when
  // taken (the worker refuses while it pools the previous one: counted).
  bool pool_balance(const std::map<std::string, Camera>& cams,
                    const std::map<std::string, RunMask>& masks,
                    const std::vector<FrameImage>& imgs) {
    if (!options.colour_balance || imgs.size() < 2) return false;
    if (pending->capture_ns < pool_from_ns) return false;  // the colours before a camera match
    if (textured_seen++ % uint64_t(options.balance_every) != 0) return false;
    BalanceWorker::Job job;
    job.rig = cams;
    job.mesh = pending->mesh;
    for (std::size_t i = 0; i < imgs.size(); ++i) {
      const auto m = masks.find(pending_cameras[i]);
      if (m == masks.end()) continue;  // its mask of the frame was lost: it takes no part
      job.cameras.push_back(pending_cameras[i]);
      job.images.push_back(imgs[i]);
      job.masks.push_back(m->second);
    }
    if (!balance.submit(std::move(job))) {
      ++counts.balance_busy;
      return false;
    }
    ++counts.balance_frames;
    return true;
  }

  // Makes `m` the rig sample when one is due: asks for its images from every calibrated camera.
  void start_rig_sample(const LiveMesh& m) {
    if (!options.colour_balance || options.balance_rig_every.count() <= 0 || rig_sample ||
        m.capture_ns < pool_from_ns || m.mesh.triangles.empty())
      return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_rig_sample < options.balance_rig_every) return;
    std::vector<std::string> ids;
    for (const auto& [id, c] : node->cameras()) ids.push_back(id);
    if (ids.size() < 2) return;
    last_rig_sample = now;
    rig_sample = RigSample{m.mesh, m.source_frame, std::move(ids), now};
    node->request_images(rig_sample->frame, rig_sample->cameras);
  }

  // Hands the rig sample to the balance's worker once every camera answered or `wait` passed
  // (the images that came, with their masks of the frame; two at least). Its worker still busy
  // with the previous one: tried again next frame, given up after a second.
  void pool_rig_sample() {
    if (!rig_sample) return;
    const auto waited = std::chrono::steady_clock::now() - rig_sample->since;
    if (waited < options.wait && !node->images_answered(rig_sample->frame, rig_sample->cameras))
      return;
    const auto cams = node->cameras();
    const auto masks = node->masks(rig_sample->frame);
    BalanceWorker::Job job;
    job.rig = cams;
    job.mesh = rig_sample->mesh;
    for (auto& [id, image] : node->images_here(rig_sample->frame, rig_sample->cameras)) {
      const auto c = cams.find(id);
      const auto m = masks.find(id);
      if (c == cams.end() || m == masks.end() || c->second.width != image.width ||
          c->second.height != image.height)
        continue;
      job.cameras.push_back(id);
      job.images.push_back(std::move(image));
      job.masks.push_back(m->second);
    }
    const std::size_t images = job.cameras.size();
    if (images < 2) {
      ++counts.balance_rig_dropped;
    } else if (rig_balance.submit(std::move(job))) {
      ++counts.balance_rig_frames;
    } else if (waited < std::chrono::seconds(1)) {
      return;  // the worker is busy: next frame
    } else {
      ++counts.balance_rig_dropped;
    }
    rig_sample.reset();
  }

  // Promotes the pending mesh when its images are here (textured) or it waited too long.
  bool promote(bool block) {
    if (!pending) return false;
    const auto waited = std::chrono::steady_clock::now() - pending_since;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(options.wait - waited);
    using Missing = PreviewNode::Missing;
    const auto imgs =
        pending_cameras.empty()
            ? std::expected<std::vector<FrameImage>, Missing>(std::unexpected(Missing::refused))
            : node->images(pending->source_frame, pending_cameras,
                           block ? std::max(left, std::chrono::milliseconds(0))
                                 : std::chrono::milliseconds(0));
    if (!imgs && imgs.error() == Missing::late && waited < options.wait) return false;
    if (auto ok = texturer.set_mesh(pending->mesh); !ok) {
      STUDIO_LOG(warn, "preview") << "mesh: " << ok.error().message;
      pending.reset();
      return false;
    }
    bool textured = imgs.has_value();
    const auto cams = node->cameras();
    const auto masks = node->masks(pending->source_frame);
    set_carving_masks(cams, masks);
    if (textured)
      for (std::size_t i = 0; i < imgs->size() && textured; ++i) {
        const auto c = cams.find(pending_cameras[i]);
        textured = c != cams.end() && c->second.width == (*imgs)[i].width &&
                   c->second.height == (*imgs)[i].height;
      }
    const bool pooled = textured && pool_balance(cams, masks, *imgs);
    std::vector<Eigen::Vector3f> gains, estimated;
    if (textured) {
      const BalanceSnapshot estimate = balance.snapshot();
      for (std::size_t i = 0; i < imgs->size() && textured; ++i) {
        const Eigen::Vector3f g =
            options.colour_balance ? estimate.gains(pending_cameras[i]) : Eigen::Vector3f::Ones();
        gains.push_back(g);
        estimated.push_back(estimate.estimated(pending_cameras[i]));
        textured =
            texturer.set_camera(int(i), cams.at(pending_cameras[i]), (*imgs)[i].rgb.data(), g)
                .has_value();
      }
    }
    current = {};
    current.gains = std::move(gains);
    current.estimated = std::move(estimated);
    current.balance_pooled = pooled;
    current.new_mesh = true;
    current.textured = textured;
    current.source_frame = pending->source_frame;
    current.cameras = pending_cameras;
    current.weights = pending_weights;
    current.carving_masks = int(carving_count);
    current_threshold = pending_threshold;
    have_current = true;
    ++counts.meshes;
    ++(textured ? counts.textured : counts.untextured);
    if (!imgs) ++(imgs.error() == Missing::late ? counts.late : counts.refused);
    pending.reset();
    return true;
  }
};

ViewPipeline::ViewPipeline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ViewPipeline::~ViewPipeline() { impl_->node->set_prefetch({}); }

Expected<std::unique_ptr<ViewPipeline>> ViewPipeline::create(PreviewNode& node,
                                                             const PipelineOptions& options) {
  if (auto ok = options.blend_options.validate(); !ok) return std::unexpected(ok.error());
  if (options.balance_every < 1) return fail("colour balance: balance_every must be >= 1");
  auto r = scene_render::Renderer::create();
  if (!r) return std::unexpected(r.error());
  if (auto ok = options.overlays.validate(); !ok) return std::unexpected(ok.error());
  auto t = ActorTexturer::create();
  if (!t) return std::unexpected(t.error());
  auto ov = OverlayRenderer::create();
  if (!ov) return std::unexpected(ov.error());
  auto impl = std::make_unique<Impl>(node, options, std::move(*r), std::move(*t), std::move(*ov));
  impl->prefetch->blend = options.blend;
  impl->prefetch->options = options.blend_options;
  // A new mesh's images are requested on arrival, for the last drawn viewpoint; the render
  // thread's own request for its choice then finds them asked (or here).
  if (options.prefetch)
    node.set_prefetch([state = impl->prefetch, n = &node](uint64_t, const Eigen::Vector3d& centre) {
      bool blend;
      BlendOptions bo;
      Eigen::Vector3d eye;
      {
        std::lock_guard lock(state->mutex);
        if (!state->have_eye) return std::vector<std::string>{};
        blend = state->blend;
        bo = state->options;
        eye = state->eye;
      }
      return choose(n->cameras(), blend, bo, eye, centre).cameras;
    });
  return std::unique_ptr<ViewPipeline>(new ViewPipeline(std::move(impl)));
}

FrameReport ViewPipeline::render(const Viewpoint& view, int width, int height, bool block) {
  Impl& r = *impl_;
  {
    std::lock_guard lock(r.prefetch->mutex);
    r.prefetch->eye = view.eye;
    r.prefetch->have_eye = true;
  }
  r.refresh_scene();
  r.take_new_mesh(view);
  const bool fresh = r.promote(block);
  r.pool_rig_sample();
  scene_render::View v;
  v.cam_from_world = scene::look_at(view.eye, view.at);
  v.clip_from_cam = scene::perspective(view.fov_deg * std::numbers::pi / 180,
                                       double(width) / height, 0.05, 200.0);
  r.renderer.draw(r.scene, v);
  FrameReport report = r.current;
  report.new_mesh = fresh;
  if (r.have_current) {
    std::array<float, ActorTexturer::kMaxCameras> w{};
    for (std::size_t i = 0; i < r.current.weights.size() && i < w.size(); ++i)
      w[i] = r.current.weights[i];
    const TextureMode mode = !r.current.textured ? TextureMode::flat
                             : r.options.blend   ? TextureMode::blend
                                                 : TextureMode::nearest;
    r.texturer.draw({v.clip_from_cam * v.cam_from_world, view.eye, width, height}, mode, w,
                    r.current_threshold);
  }
  r.draw_overlays(v.clip_from_cam * v.cam_from_world, width, height);
  return report;
}

const PipelineCounts& ViewPipeline::counts() const { return impl_->counts; }
bool ViewPipeline::has_work() const {
  return impl_->pending || impl_->node->mesh_sequence() > impl_->mesh_sequence;
}
std::vector<std::string> ViewPipeline::asset_problems() const { return impl_->problems; }
Eigen::Vector3d ViewPipeline::actor_centre() const { return impl_->centre; }
void ViewPipeline::set_blend(bool blend) {
  impl_->options.blend = blend;
  std::lock_guard lock(impl_->prefetch->mutex);
  impl_->prefetch->blend = blend;
}
bool ViewPipeline::blend() const { return impl_->options.blend; }
BalanceSnapshot ViewPipeline::colour_balance() const { return impl_->balance.snapshot(); }
BalanceSnapshot ViewPipeline::rig_colour_balance() const { return impl_->rig_balance.snapshot(); }
bool ViewPipeline::rig_sampling() const {
  return impl_->options.colour_balance && impl_->options.balance_rig_every.count() > 0;
}
void ViewPipeline::restart_colour_balance(int64_t pool_from_capture_ns) {
  impl_->pool_from_ns = pool_from_capture_ns;
  impl_->balance.restart();
  impl_->rig_balance.restart();
  impl_->rig_sample.reset();  // its images have the old colours; the next one at once
  impl_->last_rig_sample = {};
}
void ViewPipeline::finish_colour_balance() {
  impl_->balance.wait_idle();
  impl_->rig_balance.wait_idle();
}
void ViewPipeline::report(runtime::Metrics& metrics) const {
  const BalanceSnapshot b = impl_->balance.snapshot();
  metrics.gauge("colour_balance_applied").set(b.balance.applied ? 1 : 0);
  metrics.gauge("colour_balance_frames").set(b.balance.frames);
  metrics.gauge("colour_balance_off_pct").set(100.0 * largest_gain_offset(b.balance.estimated));
  const BalanceSnapshot rig = impl_->rig_balance.snapshot();
  metrics.gauge("colour_balance_rig_frames").set(rig.balance.frames);
  metrics.gauge("colour_balance_rig_linked").set(linked_cameras(rig.balance));
}
void ViewPipeline::set_colour_balance(bool on) { impl_->options.colour_balance = on; }
bool ViewPipeline::colour_balance_on() const { return impl_->options.colour_balance; }
OverlayOptions& ViewPipeline::overlays() { return impl_->options.overlays; }
ViewPipeline::Thumbnail ViewPipeline::thumbnail(const std::string& projector_id) const {
  const auto t = impl_->overlay.thumbnail(projector_id);
  return t ? Thumbnail{t->name, t->width, t->height} : Thumbnail{};
}

}  // namespace studio::preview

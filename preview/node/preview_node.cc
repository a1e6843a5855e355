#include "preview_node.h"

#include "core/clock.h"
#include "preview/camera_select.h"
#include "preview/scene_mirror.h"
#include "wire/convert.h"
#include "wire/sample.h"
#include "wire/scene_convert.h"
#include "wire_views.h"

namespace studio::preview {
namespace {

constexpr const char* kLog = "preview";
// (camera, frame) images kept for the renderer: the three texturing cameras' of 8 meshes, and
// one rig sample's (ViewPipeline's balance_rig_every: every camera of one frame) beside them, so
// that it is not trimmed while its images arrive.
constexpr std::size_t kKeptImages = 36;
constexpr std::size_t kKeptMaskFrames = 25;  // per camera: a second of masks at 25 fps

}  // namespace

struct PreviewNode::Impl {
  Impl(runtime::NodeContext& context, std::string requester_id)
      : loop(context, kLog),
        requester(std::move(requester_id)),
        requests(loop.output<studio_ImageRequest>({.counter = "image_requests", .rate = false})),
        controls(loop.output<studio_CameraControl>({.counter = "controls_sent", .rate = false})),
        captures(loop.output<studio_CaptureCommand>({.counter = "captures_sent", .rate = false})),
        scene_commands(
            loop.output<studio_SceneCommand>({.counter = "scene_commands_sent", .rate = false})),
        meshes_in(loop.counter("meshes_in")),
        images_in(loop.counter("images_in")),
        images_refused(loop.counter("image_replies_not_ok")) {
    loop.input<studio_SceneNode>(
        {.received = "scene_nodes_in", .rate = false, .instance_changes = true, .batch = 1024},
        [this](const studio_SceneNode& s, const wire::SampleMeta& m) { return on_node(s, m); });
    loop.input<studio_ActorMesh>({.received = "meshes_received"},
                                 [this](const studio_ActorMesh& s, const wire::SampleMeta&) {
                                   on_mesh(s);
                                   return runtime::Outcome{};
                                 });
    loop.input<studio_CameraCalibration>(
        {.received = "calibrations_in", .rate = false},
        [this](const studio_CameraCalibration& s, const wire::SampleMeta&) -> runtime::Outcome {
          auto c = wire::to_core(s);
          if (!c) return runtime::reject("calibration", c.error().message);
          std::lock_guard lock(mutex);
          calibrations[c->id] = *c;
          return {};
        });
    loop.input<studio_CameraState>({.received = "states_in", .rate = false},
                                   [this](const studio_CameraState& s, const wire::SampleMeta&) {
                                     on_state(s);
                                     return runtime::Outcome{};
                                   });
    loop.input<studio_ImageReply>({.received = "image_replies_in", .rate = false},
                                  [this](const studio_ImageReply& s, const wire::SampleMeta&) {
                                    on_reply(s);
                                    return runtime::Outcome{};
                                  });
    loop.input<studio_AlphaMask>(
        {.received = "masks_in", .rate = false},
        [this](const studio_AlphaMask& s, const wire::SampleMeta&) -> runtime::Outcome {
          auto m = wire::to_core(s);
          if (!m) return runtime::reject("mask", m.error().message);
          std::lock_guard lock(mutex);
          auto& kept = masks[std::string(wire::str(s.camera_id))];
          kept[s.frame] = std::move(*m);
          while (kept.size() > kKeptMaskFrames) kept.erase(kept.begin());
          return {};
        });
    loop.input<studio_ServiceStatus>(
        {.received = "statuses_in", .rate = false, .instance_changes = true},
        [this](const studio_ServiceStatus& s, const wire::SampleMeta& m) {
          std::lock_guard lock(mutex);
          ServiceView& v = services[std::string(wire::str(s.service)) + ":" +
                                    std::string(wire::str(s.instance))];
          v.service = wire::str(s.service);
          v.instance = wire::str(s.instance);
          v.alive = m.alive;
          if (!m.valid_data) return runtime::Outcome{};
          v.state = int(s.state);
          v.input_hz = s.input_hz;
          v.output_hz = s.output_hz;
          v.latency_ms = s.latency_ms;
          v.seen = std::chrono::steady_clock::now();
          return runtime::Outcome{};
        });
  }

  runtime::Outcome on_node(const studio_SceneNode& s, const wire::SampleMeta& m) {
    std::lock_guard lock(mutex);
    const std::string id(wire::str(s.node_id));
    if (!m.valid_data || m.disposed) {
      if (!m.valid_data && !m.disposed && m.alive) return {};
      nodes.erase(id);
      ++scene_version;
      return {};
    }
    auto n = wire::to_core(s);
    if (!n) return runtime::reject("scene_node", n.error().message);
    nodes[id] = std::move(*n);
    ++scene_version;
    return {};
  }

  void on_mesh(const studio_ActorMesh& s);

  void on_state(const studio_CameraState& s) {
    CameraStateView v = state_from_wire(s);
    std::lock_guard lock(mutex);
    states[v.camera_id] = std::move(v);
  }

  void on_reply(const studio_ImageReply& s) {
    if (wire::str(s.requester) != requester) return;  // another preview's
    std::lock_guard lock(mutex);
    const std::string camera(wire::str(s.camera_id));
    if (s.status != studio_IMAGE_REPLY_OK || s.format != studio_IMAGE_RGB8) {
      images_refused.add();
      store.refuse(camera, s.frame);
      changed.notify_all();
      return;
    }
    const auto d = wire::view(s.data);
    store.add(camera, {int(s.width), int(s.height), s.frame, {d.begin(), d.end()}});
    images_in.add();
    changed.notify_all();
  }

  runtime::ServiceLoop loop;
  std::string requester;
  runtime::Output<studio_ImageRequest>& requests;
  runtime::Output<studio_CameraControl>& controls;
  runtime::Output<studio_CaptureCommand>& captures;
  runtime::Output<studio_SceneCommand>& scene_commands;
  runtime::Counter& meshes_in;
  runtime::Counter& images_in;
  runtime::Counter& images_refused;
  OverlayInputs overlays{loop};  // head, projector calibrations and frames (overlay_inputs.h)

  mutable std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, Camera> calibrations;
  std::map<std::string, LiveMesh> meshes;
  std::map<std::string, std::map<uint64_t, RunMask>> masks;  // camera → frame → mask
  uint64_t mesh_sequence = 0;
  std::map<std::string, scene::Node> nodes;
  uint64_t scene_version = 0;
  std::map<std::string, CameraStateView> states;
  std::map<std::string, ServiceView> services;
  FrameImageStore store{kKeptImages};
  uint64_t request_id = 0;
  uint64_t command_id = 0;
  Prefetch prefetch;
  PreviewNode* owner = nullptr;
};

void PreviewNode::Impl::on_mesh(const studio_ActorMesh& s) {
  Prefetch f;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  {
    std::lock_guard lock(mutex);
    auto& live = meshes[std::string(wire::str(s.actor_id))];
    live.mesh = mesh_from_wire(s);
    live.source_frame = s.source_frame;
    live.capture_ns = s.capture_ns;
    live.sequence = ++mesh_sequence;
    f = prefetch;
    if (f) centre = bounds_centre(live.mesh.vertices);
  }
  meshes_in.add();
  loop.completed(s.source_frame, s.capture_ns);
  if (f) owner->request_images(s.source_frame, f(s.source_frame, centre));
}

PreviewNode::PreviewNode(runtime::NodeContext& context, std::string requester)
    : impl_(std::make_unique<Impl>(context, std::move(requester))) {
  impl_->owner = this;
}

void PreviewNode::set_prefetch(Prefetch prefetch) {
  std::lock_guard lock(impl_->mutex);
  impl_->prefetch = std::move(prefetch);
}
PreviewNode::~PreviewNode() { stop(); }
Expected<void> PreviewNode::start() { return impl_->loop.start(); }
void PreviewNode::stop() { impl_->loop.stop(); }
runtime::NodeHealth PreviewNode::health() { return impl_->loop.health(); }

const OverlayInputs& PreviewNode::overlays() const { return impl_->overlays; }

std::map<std::string, Camera> PreviewNode::cameras() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->calibrations;
}

std::map<std::string, RunMask> PreviewNode::masks(uint64_t frame) const {
  std::lock_guard lock(impl_->mutex);
  std::map<std::string, RunMask> out;
  for (const auto& [camera, kept] : impl_->masks)
    if (auto m = kept.find(frame); m != kept.end()) out.emplace(camera, m->second);
  return out;
}

std::optional<LiveMesh> PreviewNode::mesh_after(uint64_t sequence) const {
  std::lock_guard lock(impl_->mutex);
  const LiveMesh* best = nullptr;
  for (const auto& [id, m] : impl_->meshes)
    if (m.sequence > sequence && (!best || m.sequence > best->sequence)) best = &m;
  if (!best) return std::nullopt;
  return *best;
}

uint64_t PreviewNode::mesh_sequence() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->mesh_sequence;
}

std::optional<scene::Scene> PreviewNode::scene_after(uint64_t& version) const {
  std::lock_guard lock(impl_->mutex);
  if (impl_->scene_version == version) return std::nullopt;
  version = impl_->scene_version;
  return assemble_scene(impl_->nodes);
}

std::vector<CameraStateView> PreviewNode::camera_states() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<CameraStateView> out;
  for (const auto& [id, s] : impl_->states) out.push_back(s);
  return out;
}

std::vector<ServiceView> PreviewNode::services() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<ServiceView> out;
  for (const auto& [id, s] : impl_->services) out.push_back(s);
  return out;
}

void PreviewNode::request_images(uint64_t frame, const std::vector<std::string>& cameras) {
  // Called from the render thread and (prefetch) the loop thread: ids are taken under the lock.
  std::vector<std::pair<std::string, uint64_t>> wanted;
  {
    std::lock_guard lock(impl_->mutex);
    for (auto& c : impl_->store.to_request(frame, cameras))
      wanted.emplace_back(std::move(c), ++impl_->request_id);
  }
  for (const auto& [c, id] : wanted) {
    wire::Owned<studio_ImageRequest> r;
    wire::set(r->requester, impl_->requester);
    wire::set(r->camera_id, c);
    r->frame = frame;
    r->capture_ns = realtime_ns();
    r->request_id = id;
    (void)impl_->requests.write(*r);
  }
}

std::expected<std::vector<FrameImage>, PreviewNode::Missing> PreviewNode::images(
    uint64_t frame, const std::vector<std::string>& cameras, std::chrono::milliseconds wait) {
  std::unique_lock lock(impl_->mutex);
  impl_->changed.wait_for(lock, wait, [&] { return impl_->store.settled(frame, cameras); });
  return impl_->store.find(frame, cameras);
}

bool PreviewNode::images_answered(uint64_t frame, const std::vector<std::string>& cameras) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->store.answered(frame, cameras);
}

std::vector<std::pair<std::string, FrameImage>> PreviewNode::images_here(
    uint64_t frame, const std::vector<std::string>& cameras) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->store.here(frame, cameras);
}

Expected<void> PreviewNode::send_control(const std::string& camera, const std::string& feature,
                                         double value) {
  wire::Owned<studio_CameraControl> c;
  wire::set(c->camera_id, camera);
  wire::set(c->feature, feature);
  c->capture_ns = realtime_ns();
  c->value = value;
  return impl_->controls.write(*c);
}

Expected<void> PreviewNode::send_capture(const std::string& take, bool start, uint64_t at_frame) {
  wire::Owned<studio_CaptureCommand> c;
  wire::set(c->take, take);
  c->capture_ns = realtime_ns();
  c->action = start ? studio_CAPTURE_START : studio_CAPTURE_STOP;
  c->at_frame = at_frame;
  return impl_->captures.write(*c);
}

Expected<void> PreviewNode::send_scene(int verb, const std::string& target, double value,
                                       const Eigen::Vector3d& translation) {
  wire::Owned<studio_SceneCommand> c;
  c->capture_ns = realtime_ns();
  c->verb = static_cast<studio_SceneVerb>(verb);
  wire::set(c->target, target);
  c->value = value;
  c->has_value = verb == studio_SCENE_SEEK || verb == studio_SCENE_SPEED;
  for (int i = 0; i < 4; ++i) c->transform[5 * i] = 1;
  for (int i = 0; i < 3; ++i) c->transform[4 * i + 3] = translation[i];
  c->node.rotation[3] = 1;
  for (int i = 0; i < 3; ++i) c->node.scale[i] = 1;
  wire::set(c->sender, impl_->requester);
  c->command_id = ++impl_->command_id;
  c->at_frame = studio_SCENE_AT_NOW;
  c->mode = studio_SCENE_MODE_KEEP;
  return impl_->scene_commands.write(*c);
}

}  // namespace studio::preview

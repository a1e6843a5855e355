#include "hull_node.h"

#include <atomic>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <deque>
#include <thread>
#include <utility>

#include "core/clock.h"
#include "core/frame_assembler.h"
#include "core/log.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/visibility.h"
#include "segments_wire.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "wire/sample.h"
#include "yaml_io/options.h"
#include "yaml_io/rig_yaml.h"

namespace studio::hull {
namespace {

constexpr const char* kLog = "hull";
using SteadyClock = std::chrono::steady_clock;

void mesh_to_wire(const Mesh& mesh, studio_ActorMesh& s) {
  std::vector<float> v, n;
  std::vector<uint32_t> t;
  v.reserve(mesh.vertices.size() * 3);
  n.reserve(mesh.normals.size() * 3);
  t.reserve(mesh.triangles.size() * 3);
  for (const auto& p : mesh.vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
  for (const auto& p : mesh.normals) n.insert(n.end(), {p.x(), p.y(), p.z()});
  for (const auto& tri : mesh.triangles) t.insert(t.end(), tri.begin(), tri.end());
  wire::assign(s.vertices, v);
  wire::assign(s.normals, n);
  wire::assign(s.triangles, t);
}

class HullNode : public runtime::Node {
 public:
  HullNode(HullNodeOptions options, std::vector<Camera> cameras, runtime::NodeContext& ctx)
      : options_(std::move(options)),
        cameras_(std::move(cameras)),
        participant_(ctx.participant),
        metrics_(ctx.metrics),
        masks_in_(ctx.metrics.counter("masks_in")),
        masks_bad_(ctx.metrics.counter("masks_rejected")),
        frames_complete_(ctx.metrics.counter("frames_complete")),
        frames_partial_(ctx.metrics.counter("frames_partial")),
        frames_dropped_(ctx.metrics.counter("frames_dropped")),
        masks_late_(ctx.metrics.counter("masks_late")),
        hulls_out_(ctx.metrics.counter("segment_sets_out")),
        meshes_out_(ctx.metrics.counter("meshes_out")),
        calibrations_in_(ctx.metrics.counter("calibrations_in")),
        calibrations_stale_(ctx.metrics.counter("calibrations_not_of_frame")),
        tracked_(cameras_.size()),
        assembler_(make_assembler_options(options_, cameras_)) {}

  ~HullNode() override { stop(); }

  Expected<void> start() override {
    auto io = wire::gather([](auto&&... e) { return Io{std::move(e)...}; },
                           wire::Subscription<studio_AlphaMask>::create(participant_),
                           // Every per-frame pose of a tracked camera, even when a cut
                           // holds this node up (the topic keeps only the newest per camera).
                           wire::Subscription<studio_CameraCalibration>::create(
                               participant_, {}, int32_t(kTrackedHistory)),
                           wire::Publication<studio_SegmentSet>::create(participant_),
                           wire::Publication<studio_ActorMesh>::create(participant_),
                           wire::WaitSet::create(participant_),
                           wire::GuardCondition::create(participant_));
    if (!io) return std::unexpected(io.error());
    if (auto r = io->waitset.attach(*io->masks, 1); !r) return std::unexpected(r.error());
    if (auto r = io->waitset.attach(*io->cals, 2); !r) return std::unexpected(r.error());
    if (auto r = io->waitset.attach(io->guard, 3); !r) return std::unexpected(r.error());
    io_.emplace(std::move(*io));
    running_ = true;
    worker_ = std::thread([this] { run(); });
    return {};
  }

  void stop() override {
    if (!running_.exchange(false)) return;
    io_->guard.trigger();
    if (worker_.joinable()) worker_.join();
    io_.reset();
  }

  runtime::NodeHealth health() override {
    runtime::NodeHealth h;
    h.frame = last_frame_.load();
    h.capture_ns = last_capture_ns_.load();
    h.degraded = last_partial_.load();
    const auto snap_time = SteadyClock::now();
    const double dt = std::chrono::duration<double>(snap_time - last_health_).count();
    const uint64_t masks = masks_in_.value(), hulls = hulls_out_.value();
    if (dt > 0) {
      h.input_hz = double(masks - last_masks_) / dt;
      h.output_hz = double(hulls - last_hulls_) / dt;
    }
    last_health_ = snap_time;
    last_masks_ = masks;
    last_hulls_ = hulls;
    return h;
  }

 private:
  struct Io {
    wire::Subscription<studio_AlphaMask> masks;
    wire::Subscription<studio_CameraCalibration> cals;
    wire::Publication<studio_SegmentSet> segs;
    wire::Publication<studio_ActorMesh> meshes;
    wire::WaitSet waitset;
    wire::GuardCondition guard;
  };

  static typename FrameAssembler<RunMask>::Options make_assembler_options(
      const HullNodeOptions& o, const std::vector<Camera>& cams) {
    typename FrameAssembler<RunMask>::Options a;
    for (const Camera& c : cams) a.sources.push_back(c.id);
    a.deadline = std::chrono::microseconds(int64_t(o.deadline_ms * 1000));
    a.min_sources = std::size_t(o.min_cameras);
    return a;
  }

  void run() {
    while (running_) {
      auto timeout = std::chrono::nanoseconds(std::chrono::milliseconds(100));
      if (auto d = assembler_.next_deadline())
        timeout = std::max(std::chrono::nanoseconds(0), std::min(timeout, *d - SteadyClock::now()));
      io_->waitset.wait(timeout);
      if (!running_) break;
      io_->cals->visit([&](const studio_CameraCalibration& s, const wire::SampleMeta& meta) {
        if (!meta.valid_data) return;
        update_camera(s);
      });
      io_->masks->visit([&](const studio_AlphaMask& s, const wire::SampleMeta& meta) {
        if (!meta.valid_data) return;
        masks_in_.add();
        auto mask = wire::to_core(s);
        if (!mask) {
          masks_bad_.add();
          STUDIO_LOG(debug, kLog) << mask.error().message;
          return;
        }
        const int index = assembler_.source_index(s.camera_id);
        if (index >= 0 &&
            (mask->width() != cameras_[index].width || mask->height() != cameras_[index].height)) {
          masks_bad_.add();
          STUDIO_LOG(warn, kLog) << "mask " << s.camera_id << ": " << mask->width() << "x"
                                 << mask->height() << " differs from the camera's "
                                 << cameras_[index].width << "x" << cameras_[index].height;
          return;
        }
        assembler_.add(s.camera_id, s.frame, s.capture_ns, std::move(*mask), SteadyClock::now());
      });
      while (auto frame = assembler_.pop(SteadyClock::now())) process(*frame);
      sync_counts();
    }
  }

  // A fixed camera's calibration replaces the camera. A tracked camera (Free-D) sends one per
  // frame; the last kTrackedHistory are kept so that frame N is cut with the pose of frame N even
  // when the calibration of N+1 has already arrived (DESIGN §5: everything is stamped by frame).
  void update_camera(const studio_CameraCalibration& s) {
    auto cam = wire::to_core(s);
    const int index = assembler_.source_index(s.camera_id);
    if (!cam || index < 0) return;
    calibrations_in_.add();
    auto& history = tracked_[std::size_t(index)];
    if (s.tracked) {
      auto at = std::lower_bound(history.begin(), history.end(), s.frame,
                                 [](const auto& e, uint64_t f) { return e.first < f; });
      if (at != history.end() && at->first == s.frame)
        at->second = *cam;
      else
        history.insert(at, {s.frame, *cam});
      while (history.size() > kTrackedHistory) history.pop_front();
    } else {
      history.clear();
    }
    cameras_[std::size_t(index)] = std::move(*cam);
  }

  // The camera to cut `frame` with: a tracked camera's calibration of that frame, else its
  // latest one before it (counted: the pose may be a frame off), else the rig's or the last.
  const Camera& camera_for(std::size_t index, uint64_t frame) {
    const auto& history = tracked_[index];
    if (history.empty()) return cameras_[index];
    auto after = std::upper_bound(history.begin(), history.end(), frame,
                                  [](uint64_t f, const auto& e) { return f < e.first; });
    if (after == history.begin()) {
      calibrations_stale_.add();
      return history.front().second;
    }
    const auto& [at, camera] = *std::prev(after);
    if (at != frame) calibrations_stale_.add();
    return camera;
  }

  void process(const FrameAssembler<RunMask>::Frame& frame) {
    std::vector<View> views;
    for (std::size_t i = 0; i < frame.items.size(); ++i)
      if (frame.items[i]) views.push_back(View{&camera_for(i, frame.frame), &*frame.items[i]});
    CutOptions cut;
    cut.min_views = options_.min_views;
    cut.threads = options_.threads;
    auto hull = visual_hull(options_.grid_spec(), views, cut);
    if (!hull) {
      STUDIO_LOG(warn, kLog) << "frame " << frame.frame << ": " << hull.error().message;
      return;
    }
    const std::vector<SegmentSet> actors = connected_components(*hull, options_.min_actor_volume);
    for (std::size_t k = 0; k < actors.size(); ++k)
      publish(actors[k], options_.actor_prefix + std::to_string(k), frame, views, cut);
    for (std::size_t k = actors.size(); k < published_actors_; ++k)
      dispose(options_.actor_prefix + std::to_string(k));
    published_actors_ = actors.size();
    metrics_.latency().record(realtime_ns() - frame.capture_ns);
    last_frame_ = frame.frame;
    last_capture_ns_ = frame.capture_ns;
    last_partial_ = views.size() < cameras_.size();
  }

  void publish(const SegmentSet& set, const std::string& actor_id,
               const FrameAssembler<RunMask>::Frame& frame, std::span<const View> views,
               const CutOptions& cut) {
    wire::Owned<studio_SegmentSet> s;
    wire::set(s->actor_id, actor_id);
    s->frame = frame.frame;
    s->capture_ns = frame.capture_ns;
    wire::from_core(set, *s);
    if (auto r = io_->segs->write(*s); r) hulls_out_.add();
    if (!options_.mesh) return;
    wire::Owned<studio_ActorMesh> m;
    wire::set(m->actor_id, actor_id);
    m->frame = frame.frame;
    m->capture_ns = frame.capture_ns;
    m->source_frame = frame.frame;
    Mesh mesh = segment_marching_cubes(set);
    if (options_.refine) {
      // Only fails on a mask of the wrong size, which the frame's cut already rejected.
      if (auto ok = refine_crossings(mesh, set, views, cut); !ok) {
        STUDIO_LOG(warn, kLog) << "frame " << frame.frame << ": " << ok.error().message;
      }
    }
    mesh_to_wire(mesh, *m);
    if (auto r = io_->meshes->write(*m); r) meshes_out_.add();
  }

  void dispose(const std::string& actor_id) {
    wire::Owned<studio_SegmentSet> s;
    wire::set(s->actor_id, actor_id);
    (void)io_->segs->dispose(*s);
    wire::Owned<studio_ActorMesh> m;
    wire::set(m->actor_id, actor_id);
    (void)io_->meshes->dispose(*m);
  }

  // Mirrors the assembler's counts into the service metrics.
  void sync_counts() {
    const FrameAssemblerCounts& c = assembler_.counts();
    frames_complete_.add(c.complete - seen_.complete);
    frames_partial_.add(c.partial - seen_.partial);
    frames_dropped_.add(c.dropped - seen_.dropped);
    masks_late_.add(c.late - seen_.late);
    seen_ = c;
  }

  HullNodeOptions options_;
  std::vector<Camera> cameras_;
  const wire::Participant& participant_;
  runtime::Metrics& metrics_;
  runtime::Counter &masks_in_, &masks_bad_, &frames_complete_, &frames_partial_, &frames_dropped_,
      &masks_late_, &hulls_out_, &meshes_out_, &calibrations_in_, &calibrations_stale_;
  static constexpr std::size_t kTrackedHistory = 64;
  std::vector<std::deque<std::pair<uint64_t, Camera>>> tracked_;  // per camera, by frame
  FrameAssembler<RunMask> assembler_;
  FrameAssemblerCounts seen_;
  std::optional<Io> io_;
  std::atomic<bool> running_{false};
  std::thread worker_;
  std::size_t published_actors_ = 0;
  std::atomic<uint64_t> last_frame_{0};
  std::atomic<int64_t> last_capture_ns_{0};
  std::atomic<bool> last_partial_{false};
  SteadyClock::time_point last_health_ = SteadyClock::now();
  uint64_t last_masks_ = 0, last_hulls_ = 0;
};

}  // namespace

Expected<void> HullNodeOptions::validate() const {
  if (box.size() != 6) return fail("box: expected 6 numbers x0,y0,z0,x1,y1,z1");
  if (auto g = grid_spec().validate(); !g) return g;
  if (min_cameras < 1) return fail("min_cameras: must be >= 1");
  if (actor_prefix.empty() || actor_prefix.size() > 40)
    return fail("actor_prefix: 1..40 characters");
  return {};
}

GridSpec HullNodeOptions::grid_spec() const {
  GridSpec g;
  if (box.size() == 6) {
    g.box_min = Eigen::Vector3d(box[0], box[1], box[2]);
    g.box_max = Eigen::Vector3d(box[3], box[4], box[5]);
  }
  g.axis = axis;
  g.cells_u = grid;
  g.cells_v = grid;
  return g;
}

Expected<std::unique_ptr<runtime::Node>> make_hull_node(const HullNodeOptions& options,
                                                        std::vector<Camera> cameras,
                                                        runtime::NodeContext& context) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  if (cameras.empty()) return fail("rig " + options.rig + ": no cameras");
  if (std::size_t(options.min_cameras) > cameras.size())
    return fail("min_cameras " + std::to_string(options.min_cameras) + " exceeds the rig's " +
                std::to_string(cameras.size()) + " cameras");
  GridSpec sampled = options.grid_spec();  // a fraction: 128 x 128 columns at most suffice
  sampled.cells_u = sampled.cells_v = std::min(sampled.cells_u, 128);
  if (auto c = coverage(sampled, cameras, options.min_views); c) {
    STUDIO_LOG(info, kLog) << "box coverage: " << 100 * c->unseen << " % seen by no camera, "
                           << 100 * c->below_min_views << " % by fewer than " << c->min_views;
  }
  return std::unique_ptr<runtime::Node>(new HullNode(options, std::move(cameras), context));
}

runtime::ServiceDefinition hull_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "hull";
  d.summary =
      "Real-time line-segment visual hull: masks of every camera -> per-actor segments and mesh.";
  d.config_help =
      "  hull:                     (required section)\n"
      "    rig: FILE               rig.yaml with the cameras (relative to the config file)\n"
      "    box: [x0,y0,z0,x1,y1,z1] reconstruction volume, studio frame, metres\n"
      "    grid: 128               columns per side (8..2048)\n"
      "    axis: y                 continuous axis of the segments: x|y|z\n"
      "    deadline_ms: 40         wait for a frame's missing masks at most this long\n"
      "    min_cameras: 2          drop a frame with fewer masks at its deadline\n"
      "    min_views: 2            actor = inside every silhouette that sees it AND seen by\n"
      "                            >= min_views cameras (0..64; see studio-hull offline --help)\n"
      "    threads: 2              cut threads\n"
      "    mesh: true              publish studio/actor/mesh\n"
      "    refine: true            exact crossings on the mesh (else half-cell vertices)\n"
      "    min_actor_volume: 0.01  smaller components (m^3) are noise\n"
      "    actor_prefix: actor     actor ids <prefix>0, <prefix>1, ... largest first\n";
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto section = config.required("hull");
    if (!section) return std::unexpected(section.error());
    static const yaml::Schema<HullNodeOptions> schema{
        yaml::field("rig", &HullNodeOptions::rig).required().relative_path(),
        yaml::field("box", &HullNodeOptions::box).required().size(6),
        yaml::field("grid", &HullNodeOptions::grid).range(8, 2048),
        yaml::enum_field("axis", &HullNodeOptions::axis,
                         {{"x", Axis::x}, {"y", Axis::y}, {"z", Axis::z}}),
        yaml::field("deadline_ms", &HullNodeOptions::deadline_ms).range(1, 1000),
        yaml::field("min_cameras", &HullNodeOptions::min_cameras).range(1, 64),
        yaml::field("min_views", &HullNodeOptions::min_views).range(0, 64),
        yaml::field("threads", &HullNodeOptions::threads).range(1, 64),
        yaml::field("mesh", &HullNodeOptions::mesh),
        yaml::field("refine", &HullNodeOptions::refine),
        yaml::field("min_actor_volume", &HullNodeOptions::min_actor_volume).min(0),
        yaml::field("actor_prefix", &HullNodeOptions::actor_prefix),
    };
    auto options = schema.read(*section);
    if (!options) return std::unexpected(options.error());
    auto rig = yaml::read_rig(options->rig);
    if (!rig) return std::unexpected(rig.error());
    return make_hull_node(*options, rig->cameras, ctx);
  };
  return d;
}

}  // namespace studio::hull

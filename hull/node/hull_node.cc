#include "hull_node.h"

#include <chrono>
#include <map>
#include <optional>
#include <utility>

#include "actor_outputs.h"
#include "core/clock.h"
#include "core/frame_assembler.h"
#include "core/log.h"
#include "hull/camera_poses.h"
#include "hull/visibility.h"
#include "hull_stages.h"
#include "runtime/service_loop.h"
#include "wire/actor_convert.h"
#include "wire/convert.h"
#include "wire/sample.h"

namespace studio::hull {
namespace {

constexpr const char* kLog = "hull";
using SteadyClock = std::chrono::steady_clock;
using Assembler = FrameAssembler<RunMask>;

Assembler::Options assembler_options(const HullNodeOptions& o, const std::vector<Camera>& cams) {
  Assembler::Options a;
  for (const Camera& c : cams) a.sources.push_back(c.id);
  a.deadline = std::chrono::microseconds(int64_t(o.deadline_ms * 1000));
  a.min_sources = std::size_t(o.min_cameras);
  return a;
}

// Runs on runtime::ServiceLoop: masks and calibrations in, per frame a cut and per actor its
// segments and mesh out (hull_node.h).
class HullNode : public runtime::Node {
 public:
  HullNode(HullNodeOptions options, std::vector<Camera> cameras, std::vector<Camera> projectors,
           runtime::NodeContext& ctx)
      : options_(std::move(options)),
        assembler_(assembler_options(options_, cameras)),
        poses_(std::move(cameras)),
        projectors_(std::move(projectors)),
        stages_(ctx.metrics),
        loop_(ctx, kLog) {
    outputs_.emplace(loop_, options_);
    if (options_.projector_masks) {
      // The projectors' own calibrations (studio-projector publishes its rig entry, transient
      // local): a projector not in our rig joins, one in it is replaced.
      loop_.input<studio_ProjectorCalibration>(
          {.received = "projector_calibrations_in",
           .rejected = "projector_calibrations_rejected",
           .reason_prefix = "projector_calibrations_rejected_",
           .rate = false},
          [this](const studio_ProjectorCalibration& s, const wire::SampleMeta&) {
            return on_projector_calibration(s);
          });
    }
    // Every per-frame pose of a tracked camera, even when a cut holds this node up (the topic
    // keeps only the newest per camera).
    loop_.input<studio_CameraCalibration>(
        {.received = "calibrations_in",
         .rejected = "calibrations_rejected",
         .reason_prefix = "calibrations_rejected_",
         .rate = false,
         .history_depth = int32_t(CameraPoses::kDefaultHistory)},
        [this](const studio_CameraCalibration& s, const wire::SampleMeta&) {
          return on_calibration(s);
        });
    loop_.input<studio_CameraState>(
        {.received = "camera_states_in", .rejected = "camera_states_rejected", .rate = false},
        [this](const studio_CameraState& s, const wire::SampleMeta&) {
          if (const int i = assembler_.source_index(s.camera_id); i >= 0)
            poses_.set_valid(std::size_t(i), s.calibration_valid);
          return runtime::Outcome{};
        });
    loop_.input<studio_AlphaMask>(
        {.received = "masks_in", .rejected = "masks_rejected", .reason_prefix = "masks_rejected_"},
        [this](const studio_AlphaMask& s, const wire::SampleMeta& m) { return on_mask(s, m); });
    loop_.after_inputs([this](SteadyClock::time_point now) { emit(now); });
    loop_.deadline([this] { return assembler_.next_deadline(); },
                   [this](SteadyClock::time_point now) { emit(now); });
    for (const char* name : {"frames_complete", "frames_partial", "frames_dropped", "masks_late"})
      frame_counts_.push_back(&loop_.counter(name));
    stale_ = &loop_.counter("calibrations_not_of_frame");
    invalid_ = &loop_.counter("masks_of_invalid_calibration");
  }
  ~HullNode() override { stop(); }

  Expected<void> start() override { return loop_.start(); }
  void stop() override { loop_.stop(); }
  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    h.degraded = last_partial_;
    return h;
  }

 private:
  // A calibration of one of our cameras: fixed ones are replaced, tracked ones kept by frame.
  runtime::Outcome on_calibration(const studio_CameraCalibration& s) {
    const int index = assembler_.source_index(s.camera_id);
    if (index < 0) return {};  // another rig's camera
    auto cam = wire::to_core(s);
    if (!cam) return runtime::reject("to_core", cam.error().message);
    poses_.update(std::size_t(index), s.frame, s.tracked, std::move(*cam));
    return {};
  }

  runtime::Outcome on_projector_calibration(const studio_ProjectorCalibration& s) {
    auto p = wire::to_core(s);
    if (!p) return runtime::reject("to_core", p.error().message);
    for (Camera& c : projectors_)
      if (c.id == p->camera.id) {
        c = p->camera;
        return {};
      }
    projectors_.push_back(p->camera);
    return {};
  }

  runtime::Outcome on_mask(const studio_AlphaMask& s, const wire::SampleMeta& meta) {
    auto mask = wire::to_core(s);
    if (!mask) return runtime::reject("to_core", mask.error().message);
    const int index = assembler_.source_index(s.camera_id);
    if (index >= 0) {
      const Camera& c = poses_.latest(std::size_t(index));
      if (mask->width() != c.width || mask->height() != c.height)
        return runtime::reject(
            "size", "mask " + std::string(s.camera_id) + ": " + std::to_string(mask->width()) +
                        "x" + std::to_string(mask->height()) + " differs from the camera's " +
                        std::to_string(c.width) + "x" + std::to_string(c.height));
    }
    const auto now = SteadyClock::now();
    assembler_.add(s.camera_id, s.frame, s.capture_ns, std::move(*mask), now);
    // The frame's newest mask so far: when it was handled, and its transport (hull_stages.h).
    auto [it, first] = arrivals_.try_emplace(s.frame);
    Arrival& a = it->second;
    if (first) a.first = now;
    a.handled = now;
    a.delivery_ms =
        meta.source_timestamp ? double(realtime_ns() - meta.source_timestamp) * 1e-6 : -1;
    a.written_ms = meta.source_timestamp ? double(meta.source_timestamp - s.capture_ns) * 1e-6 : -1;
    if (arrivals_.size() > 64) arrivals_.erase(arrivals_.begin());  // frames never cut
    return {};
  }

  // Cuts every frame the assembler lets go (complete, or at its deadline) and mirrors its counts.
  void emit(SteadyClock::time_point now) {
    while (auto frame = assembler_.pop(now)) process(*frame);
    const FrameAssemblerCounts& c = assembler_.counts();
    const uint64_t counts[] = {c.complete, c.partial, c.dropped, c.late};
    const uint64_t seen[] = {seen_.complete, seen_.partial, seen_.dropped, seen_.late};
    for (std::size_t k = 0; k < frame_counts_.size(); ++k)
      frame_counts_[k]->add(counts[k] - seen[k]);
    seen_ = c;
  }

  void process(const Assembler::Frame& frame) {
    auto t = SteadyClock::now();
    std::optional<SteadyClock::time_point> last_mask;
    if (auto it = arrivals_.find(frame.frame); it != arrivals_.end()) {
      last_mask = it->second.handled;
      if (it->second.delivery_ms >= 0) {
        stages_.add(HullStages::mask_delivery, it->second.delivery_ms);
        stages_.add(HullStages::capture_to_mask, it->second.written_ms);
      }
      stages_.add(HullStages::assembly, it->second.handled - it->second.first);
      stages_.add(HullStages::queue, t - it->second.handled);
    }
    arrivals_.erase(arrivals_.begin(), arrivals_.upper_bound(frame.frame));
    std::vector<View> views;
    for (std::size_t i = 0; i < frame.items.size(); ++i) {
      if (!frame.items[i]) continue;
      if (!poses_.valid(i)) {  // its calibration no longer describes it: leave it out
        invalid_->add();
        continue;
      }
      const CameraPoses::Pose pose = poses_.camera_for(i, frame.frame);
      if (pose.stale) stale_->add();
      views.push_back(View{pose.camera, &*frame.items[i]});
    }
    CutOptions cut;
    cut.min_views = options_.min_views;
    cut.threads = options_.threads;
    auto hull = visual_hull(options_.grid_spec(), views, cut);
    if (!hull) {
      STUDIO_LOG(warn, kLog) << "frame " << frame.frame << ": " << hull.error().message;
      return;
    }
    const std::vector<SegmentSet> actors = connected_components(*hull, options_.min_actor_volume);
    const auto cut_done = SteadyClock::now();
    stages_.add(HullStages::cut, cut_done - t);
    ActorOutputs::Durations d;
    const ActorOutputs::FrameId id{frame.frame, frame.capture_ns};
    for (std::size_t k = 0; k < actors.size(); ++k)
      outputs_->actor(actors[k], options_.actor_prefix + std::to_string(k), id, views, cut, d);
    stages_.add(HullStages::mesh, d.mesh);
    stages_.add(HullStages::refine, d.refine);
    stages_.add(HullStages::publish, d.publish);
    if (last_mask && !actors.empty())
      stages_.add(HullStages::mask_to_mesh, SteadyClock::now() - *last_mask);
    for (std::size_t k = actors.size(); k < published_actors_; ++k)
      outputs_->dispose(options_.actor_prefix + std::to_string(k));
    published_actors_ = actors.size();
    loop_.completed(frame.frame, frame.capture_ns);
    last_partial_ = views.size() < poses_.size();
    outputs_->projector_masks(id, projectors_, views, cut);
  }

  HullNodeOptions options_;
  Assembler assembler_;
  CameraPoses poses_;
  FrameAssemblerCounts seen_;
  std::size_t published_actors_ = 0;
  std::atomic<bool> last_partial_{false};
  std::vector<Camera> projectors_;
  std::optional<ActorOutputs> outputs_;  // made on loop_ in the constructor
  std::vector<runtime::Counter*> frame_counts_;
  runtime::Counter* stale_ = nullptr;
  runtime::Counter* invalid_ = nullptr;
  struct Arrival {
    SteadyClock::time_point first;    // the frame's first mask handled
    SteadyClock::time_point handled;  // its newest
    double delivery_ms = -1;          // -1: no source timestamp
    double written_ms = -1;           // capture_ns -> written
  };
  std::map<uint64_t, Arrival> arrivals_;  // frame -> its first and newest mask (loop thread)
  HullStages stages_;
  runtime::ServiceLoop loop_;  // last: stopped before the state above goes
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_hull_node(const HullNodeOptions& options,
                                                        std::vector<Camera> cameras,
                                                        runtime::NodeContext& context,
                                                        std::vector<Camera> projectors) {
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
  return std::unique_ptr<runtime::Node>(
      new HullNode(options, std::move(cameras), std::move(projectors), context));
}

}  // namespace studio::hull

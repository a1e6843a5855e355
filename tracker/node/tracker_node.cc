#include "core/clock.h"
#include "tracker_node.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/log.h"
#include "tracker/segment_raster.h"
#include "wire/actor_convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"

namespace studio::tracker::node {
namespace {

constexpr std::string_view kCategory = "tracker";
using Clock = std::chrono::steady_clock;


}  // namespace

// Everything the worker thread owns; created by start(), destroyed by stop().
struct TrackerNode::Worker {
  enum : dds_attach_t { kData = 1, kStop = 2 };

  const NodeOptions& options;
  runtime::Metrics& metrics;
  wire::Subscription<studio_SegmentSet> segments;
  wire::Publication<studio_HeadPose> heads;
  wire::GuardCondition stop_guard;
  wire::WaitSet waitset;
  HeadSearch search;
  HeadTracker tracker;

  runtime::Counter& sets_in;
  runtime::Counter& heads_out;
  runtime::Counter& empty_hulls;
  runtime::Counter& keepalives;
  runtime::Counter& rejected;
  runtime::Counter& late_sets;
  uint64_t reader_rejects_seen = 0;

  // The frame being gathered: the hull publishes each actor (connected component) of a frame as
  // its own SegmentSet, and the tracker must see every head of a frame in one update, or each
  // update would miss the other actors' heads.
  struct Gathered {
    uint64_t frame = 0;
    int64_t capture_ns = 0;
    std::vector<HeadDetection> heads;
    Clock::time_point deadline;
  };
  std::optional<Gathered> gathering{};

  std::atomic<bool> running{true};
  std::atomic<uint64_t> last_frame{0};
  std::atomic<int64_t> last_capture_ns{0};
  std::atomic<bool> lost{true};

  OccupancyGrid grid{};
  HeadPose last_pose{};     // last published primary pose (coasted by keep-alives)
  uint64_t pose_frame = 0;  // source frame of last_pose
  int64_t source_ns = 0;    // capture_ns of the last real frame
  Clock::time_point source_arrival = Clock::now();
  Clock::time_point last_publish = Clock::now();
  int coasted_ticks = 0;
  bool have_source = false;
  wire::Owned<studio_HeadPose> out{};

  void publish(const HeadPose& pose, const std::string& id, uint64_t frame) {
    wire::set(out->actor_id, id);
    out->frame = frame;
    wire::from_core(pose, *out);
    if (auto r = heads->write(*out); !r) {
      STUDIO_LOG(warn, kCategory) << r.error().message;
      return;
    }
    heads_out.add();
  }

  void publish_primary(const HeadPose& pose, uint64_t frame) {
    last_pose = pose;
    pose_frame = frame;
    lost = pose.confidence <= 0;
    publish(pose, options.actor_id, frame);
    last_publish = Clock::now();
  }

  // One SegmentSet: its heads join the frame being gathered (another frame first flushes that).
  void on_segments(const studio_SegmentSet& s) {
    sets_in.add();
    auto set = wire::to_core(s);
    if (!set) {
      rejected.add();
      STUDIO_LOG(warn, kCategory) << set.error().message;
      return;
    }
    if (gathering && (gathering->frame != s.frame || gathering->capture_ns != s.capture_ns)) {
      flush();
    }
    if (!gathering) {
      // A set of the frame last updated came after its window closed: a separate update.
      if (have_source && s.frame == last_frame && s.capture_ns == source_ns) late_sets.add();
      gathering = Gathered{s.frame, s.capture_ns, {},
                           Clock::now() + std::chrono::microseconds(
                                              int64_t(options.gather_ms * 1000))};
    }
    if (set->interval_count() == 0) {
      empty_hulls.add();
    } else {
      rasterise(*set, &grid);
      for (const HeadDetection& h : search.find(grid)) gathering->heads.push_back(h);
    }
  }

  // The gathered frame's heads as one tracker update, and its poses out.
  void flush() {
    if (!gathering) return;
    Gathered g = std::move(*gathering);
    gathering.reset();
    // A source clock that jumps back (a replay looping) would freeze the filter: start over.
    if (have_source && g.capture_ns + int64_t(1'000'000'000) < source_ns) {
      STUDIO_LOG(info, kCategory) << "capture time went back " << (source_ns - g.capture_ns) * 1e-9
                                  << " s: tracks reset";
      tracker = HeadTracker::create(options.filter).value();
    }
    tracker.update(g.heads, g.capture_ns);
    have_source = true;
    source_ns = g.capture_ns;
    source_arrival = Clock::now();
    coasted_ticks = 0;
    last_frame = g.frame;
    last_capture_ns = g.capture_ns;

    HeadPose primary = tracker.primary();
    primary.capture_ns = g.capture_ns;
    publish_primary(primary, g.frame);
    if (options.publish_tracks)
      for (const HeadPose& p : tracker.poses())
        publish(p, options.actor_id + "/" + std::to_string(p.actor_id), g.frame);
    metrics.latency().record(realtime_ns() - g.capture_ns);
  }

  void keep_alive() {
    const double dt = 1.0 / options.publish_rate;
    HeadPose p = last_pose;
    ++coasted_ticks;
    if (coasted_ticks > options.filter.max_missed || p.confidence <= 0) {
      p.velocity.setZero();
      p.confidence = 0;
    } else {
      p.position += p.velocity * dt;
      p.velocity *= options.filter.coast_decay;
      p.confidence *= options.filter.coast_decay;
    }
    if (have_source)
      p.capture_ns = source_ns + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     Clock::now() - source_arrival)
                                     .count();
    keepalives.add();
    publish_primary(p, pose_frame);
  }

  void run() {
    const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / options.publish_rate));
    while (running) {
      Clock::time_point wake = last_publish + period;
      if (gathering) wake = std::min(wake, gathering->deadline);
      const auto wait = std::max(Clock::duration::zero(), wake - Clock::now());
      const auto triggered = waitset.wait(wait);
      if (std::find(triggered.begin(), triggered.end(), dds_attach_t(kStop)) != triggered.end())
        break;
      segments->visit([&](const studio_SegmentSet& s, const wire::SampleMeta& meta) {
        if (meta.valid_data) on_segments(s);
      });
      if (gathering && Clock::now() >= gathering->deadline) flush();
      const uint64_t total = segments->rejected().total();
      if (total > reader_rejects_seen) {
        rejected.add(total - reader_rejects_seen);
        reader_rejects_seen = total;
      }
      if (Clock::now() >= last_publish + period) keep_alive();
    }
  }
};

TrackerNode::TrackerNode(NodeOptions options, runtime::NodeContext& context)
    : options_(std::move(options)), participant_(context.participant), metrics_(context.metrics) {
  // Registered up front so the status shows them at zero.
  for (const char* name : {"segment_sets_in", "heads_out", "empty_hulls", "keepalives", "rejected",
                           "late_segment_sets"})
    metrics_.counter(name);
}

TrackerNode::~TrackerNode() { stop(); }

Expected<void> TrackerNode::start() {
  if (worker_) return {};
  auto segments = wire::Subscription<studio_SegmentSet>::create(participant_);
  if (!segments) return std::unexpected(segments.error());
  auto heads = wire::Publication<studio_HeadPose>::create(participant_);
  if (!heads) return std::unexpected(heads.error());
  auto guard = wire::GuardCondition::create(participant_);
  if (!guard) return std::unexpected(guard.error());
  auto waitset = wire::WaitSet::create(participant_);
  if (!waitset) return std::unexpected(waitset.error());
  if (auto r = waitset->attach(segments->reader, Worker::kData); !r) return std::unexpected(r.error());
  if (auto r = waitset->attach(*guard, Worker::kStop); !r) return std::unexpected(r.error());
  auto search = HeadSearch::create(options_.search);
  if (!search) return std::unexpected(search.error());
  auto tracker = HeadTracker::create(options_.filter);
  if (!tracker) return std::unexpected(tracker.error());

  worker_.reset(new Worker{.options = options_,
                           .metrics = metrics_,
                           .segments = std::move(*segments),
                           .heads = std::move(*heads),
                           .stop_guard = std::move(*guard),
                           .waitset = std::move(*waitset),
                           .search = std::move(*search),
                           .tracker = std::move(*tracker),
                           .sets_in = metrics_.counter("segment_sets_in"),
                           .heads_out = metrics_.counter("heads_out"),
                           .empty_hulls = metrics_.counter("empty_hulls"),
                           .keepalives = metrics_.counter("keepalives"),
                           .rejected = metrics_.counter("rejected"),
                           .late_sets = metrics_.counter("late_segment_sets")});
  worker_->last_pose = worker_->tracker.primary();  // rest position, confidence 0
  thread_ = std::thread([w = worker_.get()] { w->run(); });
  return {};
}

void TrackerNode::stop() {
  if (!worker_) return;
  worker_->running = false;
  worker_->stop_guard.trigger();
  if (thread_.joinable()) thread_.join();
  worker_.reset();
}

runtime::NodeHealth TrackerNode::health() {
  runtime::NodeHealth h;
  if (!worker_) return h;
  h.frame = worker_->last_frame;
  h.capture_ns = worker_->last_capture_ns;
  h.degraded = worker_->lost;  // running, but no head tracked
  return h;
}

runtime::ServiceDefinition service_definition() {
  runtime::ServiceDefinition d;
  d.name = "tracker";
  d.summary =
      "Head tracker node: studio/actor/segments (SegmentSet) in, studio/actor/head (HeadPose)\n"
      "out (two-box template search, TCSVT 2004 IV-D, plus Kalman tracks). Offline mode:\n"
      "  studio-tracker locate --help";
  d.config_help = kConfigHelp;
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& context) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = read_node_options(config);
    if (!options) return std::unexpected(options.error());
    return std::make_unique<TrackerNode>(std::move(*options), context);
  };
  return d;
}

}  // namespace studio::tracker::node

#include "tracker_node.h"

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "core/log.h"
#include "runtime/service_loop.h"
#include "segments_wire.h"
#include "tracker/keep_alive.h"
#include "tracker/segment_raster.h"

namespace studio::tracker::node {
namespace {

constexpr const char* kLog = "tracker";
using Clock = std::chrono::steady_clock;

class TrackerNode : public runtime::Node {
 public:
  TrackerNode(NodeOptions options, HeadSearch search, HeadTracker tracker,
              runtime::NodeContext& context)
      : options_(std::move(options)),
        search_(std::move(search)),
        tracker_(std::move(tracker)),
        keep_alive_(options_.filter, options_.publish_rate, tracker_.primary(), Clock::now()),
        loop_(context, kLog) {
    heads_ = &loop_.output<studio_HeadPose>({.counter = "heads_out"});
    empty_hulls_ = &loop_.counter("empty_hulls");
    keepalives_ = &loop_.counter("keepalives");
    late_sets_ = &loop_.counter("late_segment_sets");
    loop_.input<studio_SegmentSet>(
        {.received = "segment_sets_in"},
        [this](const studio_SegmentSet& s, const wire::SampleMeta&) { return on_segments(s); });
    // The gather window of the frame being gathered, then the keep-alive.
    loop_.deadline(
        [this] { return gathering_ ? std::optional(gathering_->deadline) : std::nullopt; },
        [this](Clock::time_point) { flush(); });
    loop_.deadline([this] { return std::optional(keep_alive_.due()); },
                   [this](Clock::time_point now) { keep_alive(now); });
  }
  ~TrackerNode() override { stop(); }

  Expected<void> start() override { return loop_.start(); }
  void stop() override { loop_.stop(); }
  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    h.degraded = lost_;  // running, but no head tracked
    return h;
  }

 private:
  // The frame being gathered: the hull publishes each actor (connected component) of a frame as
  // its own SegmentSet, and the tracker must see every head of a frame in one update, or each
  // update would miss the other actors' heads.
  struct Gathered {
    uint64_t frame = 0;
    int64_t capture_ns = 0;
    std::vector<HeadDetection> heads;
    Clock::time_point deadline;
  };

  // One SegmentSet: its heads join the frame being gathered (another frame first flushes that).
  runtime::Outcome on_segments(const studio_SegmentSet& s) {
    auto set = wire::to_core(s);
    if (!set) return runtime::reject("to_core", set.error().message);
    if (gathering_ && (gathering_->frame != s.frame || gathering_->capture_ns != s.capture_ns))
      flush();
    if (!gathering_) {
      // A set of the frame last updated came after its window closed: a separate update.
      if (have_source_ && s.frame == source_frame_ && s.capture_ns == source_ns_) late_sets_->add();
      const auto window = std::chrono::microseconds(int64_t(options_.gather_ms * 1000));
      gathering_ = Gathered{s.frame, s.capture_ns, {}, Clock::now() + window};
    }
    if (set->interval_count() == 0) {
      empty_hulls_->add();
    } else {
      rasterise(*set, &grid_);
      for (const HeadDetection& h : search_.find(grid_)) gathering_->heads.push_back(h);
    }
    return {};
  }

  // The gathered frame's heads as one tracker update, and its poses out.
  void flush() {
    if (!gathering_) return;
    Gathered g = std::move(*gathering_);
    gathering_.reset();
    // A source clock that jumps back (a replay looping) would freeze the filter: start over.
    if (have_source_ && g.capture_ns + int64_t(1'000'000'000) < source_ns_) {
      STUDIO_LOG(info, kLog) << "capture time went back " << (source_ns_ - g.capture_ns) * 1e-9
                             << " s: tracks reset";
      tracker_ = HeadTracker::create(options_.filter).value();
    }
    tracker_.update(g.heads, g.capture_ns);
    have_source_ = true;
    source_ns_ = g.capture_ns;
    source_frame_ = g.frame;

    HeadPose primary = tracker_.primary();
    primary.capture_ns = g.capture_ns;
    publish(primary, options_.actor_id, g.frame);
    keep_alive_.frame(primary, g.frame, Clock::now());
    lost_ = keep_alive_.lost();
    if (options_.publish_tracks)
      for (const HeadPose& p : tracker_.poses())
        publish(p, options_.actor_id + "/" + std::to_string(p.actor_id), g.frame);
    loop_.completed(g.frame, g.capture_ns);
  }

  void keep_alive(Clock::time_point now) {
    const HeadPose p = keep_alive_.tick(now);
    keepalives_->add();
    lost_ = keep_alive_.lost();
    publish(p, options_.actor_id, keep_alive_.frame_number());
  }

  void publish(const HeadPose& pose, const std::string& id, uint64_t frame) {
    wire::set(out_->actor_id, id);
    out_->frame = frame;
    wire::from_core(pose, *out_);
    (void)heads_->write(*out_);
  }

  NodeOptions options_;
  HeadSearch search_;
  HeadTracker tracker_;
  KeepAlive keep_alive_;
  std::optional<Gathered> gathering_;
  OccupancyGrid grid_{};
  bool have_source_ = false;
  uint64_t source_frame_ = 0;  // frame and capture_ns of the last real update
  int64_t source_ns_ = 0;
  std::atomic<bool> lost_{true};
  wire::Owned<studio_HeadPose> out_{};
  runtime::Output<studio_HeadPose>* heads_ = nullptr;
  runtime::Counter *empty_hulls_ = nullptr, *keepalives_ = nullptr, *late_sets_ = nullptr;
  runtime::ServiceLoop loop_;  // last: stopped before the state above goes
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_tracker_node(NodeOptions options,
                                                           runtime::NodeContext& context) {
  auto search = HeadSearch::create(options.search);
  if (!search) return std::unexpected(search.error());
  auto tracker = HeadTracker::create(options.filter);
  if (!tracker) return std::unexpected(tracker.error());
  return std::make_unique<TrackerNode>(std::move(options), std::move(*search), std::move(*tracker),
                                       context);
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
    return make_tracker_node(std::move(*options), context);
  };
  return d;
}

}  // namespace studio::tracker::node

#include "scene_server.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/clock.h"
#include "core/log.h"
#include "runtime/service_loop.h"
#include "scene/scene.h"
#include "scene_loading.h"
#include "state_file.h"
#include "wire/scene_convert.h"

namespace studio::scene::node {
namespace {

constexpr const char* kLog = "scene";
using Clock = std::chrono::steady_clock;

class SceneServer : public runtime::Node {
 public:
  SceneServer(NodeOptions options, PersistedState state, scene_assets::AssetCache cache,
              std::optional<WriteAheadLog> wal, runtime::NodeContext& context)
      : options_(std::move(options)),
        wal_(std::move(wal)),
        scene_(std::move(state.scene)),
        cache_(std::move(cache)),
        published_(std::move(state.published)),
        instance_(context.instance.empty() ? "scene" : context.instance),
        sequence_(state.sequence),
        loop_(context, kLog) {
    nodes_out_ = &loop_.output<studio_SceneNode>({.counter = "nodes_published"});
    state_out_ = &loop_.output<studio_SceneState>({.counter = "states_published", .rate = false});
    commands_ = &loop_.input<studio_SceneCommand>(
        {.received = "commands_in", .batch = 256, .history_depth = options_.command_queue},
        [this](const studio_SceneCommand& c, const wire::SampleMeta&) { return on_command(c); });
    accepted_ = &loop_.counter("commands_accepted");
    rejected_ = &loop_.counter("rejected");
    lost_ = &loop_.counter("commands_lost");
    malformed_ = &loop_.counter("rejected_malformed");
    ticks_ = &loop_.counter("ticks");
    disposed_ = &loop_.counter("nodes_disposed");
    persists_ = &loop_.counter("persists");
    syncs_ = &loop_.counter("syncs");
    persist_failures_ = &loop_.counter("persist_failures");
    publish_failures_ = &loop_.counter("publish_failures");
    loop_.after_inputs([this](Clock::time_point now) { flush(now); });
    // The studio clock: one Tick per frame, at the frame's start.
    if (options_.clock_source == ClockSource::studio)
      loop_.deadline([this] { return std::optional(next_tick_); },
                     [this](Clock::time_point now) { flush(now); });
    // Tick-only changes persisted at a bounded interval; the durable copy by the syncer.
    if (!options_.state_dir.empty()) {
      loop_.thread(
          "scene-sync", [this] { sync_loop(); },
          [this] {
            { std::lock_guard lock(sync_mutex_); }
            sync_wake_.notify_all();
          });
      loop_.every(std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(options_.persist_interval)),
                  [this](Clock::time_point) {
                    if (unpersisted_) persist();
                  });
    }
  }
  ~SceneServer() override { stop(); }

  Expected<void> start() override {
    if (auto ok = loop_.start(); !ok) return ok;
    loop_.wake();  // publishes the scene at once, whatever the clock source
    return {};
  }
  void stop() override {
    loop_.stop();
    // A clean stop leaves the durable copy current.
    std::shared_ptr<const std::vector<std::uint8_t>> bytes;
    {
      std::lock_guard lock(sync_mutex_);
      bytes = std::move(to_sync_);
    }
    if (bytes) sync(*bytes);
  }
  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    h.degraded = persist_failing_.load();  // running, but changes are not persisted
    return h;
  }

 private:
  // The studio frame now (DESIGN §5); the scene's own frame when the clock is the commands'.
  int64_t now_frame() const {
    if (options_.clock_source == ClockSource::commands) return scene_.frame();
    return std::max<int64_t>(0, options_.frame_at(realtime_ns()));
  }

  runtime::Outcome on_command(const studio_SceneCommand& s) {
    handled_ = true;
    last_sender_ = s.sender;
    last_id_ = s.command_id;
    // command_id gaps per sender: commands lost on the way (or dropped from a full queue).
    if (s.command_id != 0) {
      auto [it, fresh] = next_id_.try_emplace(s.sender, s.command_id);
      if (!fresh && s.command_id > it->second) skipped_ += s.command_id - it->second;
      if (fresh || s.command_id >= it->second) it->second = s.command_id + 1;
    }
    if (s.capture_ns > 0) newest_capture_ns_ = s.capture_ns;
    auto outcome = apply(s);
    last_accepted_ = outcome.has_value();
    if (outcome) {
      accepted_->add();
      accepted_since_persist_ = true;
    } else {
      last_error_ = outcome.error().reason + ": " + outcome.error().detail;
    }
    return outcome;
  }

  runtime::Outcome apply(const studio_SceneCommand& s) {
    if (s.verb == studio_SCENE_LOAD_SET) return load_set(s);
    auto command = wire::to_core(s, now_frame());
    if (!command) return runtime::reject("convert", command.error().message);
    if (auto ok = scene_.apply(*command); !ok)
      return runtime::reject(command_name(command->op), ok.error().message);
    return {};
  }

  // The scene file replaces the whole scene, all or nothing; nodes it lacks are disposed.
  runtime::Outcome load_set(const studio_SceneCommand& s) {
    const int64_t frame = s.at_frame == studio_SCENE_AT_NOW ? now_frame() : s.at_frame;
    if (frame < 0)
      return runtime::reject("load_set", "frame " + std::to_string(frame) + " out of range");
    const std::string path = resolve_path(options_.base_dir, s.path);
    auto built = load_scene_file(path, scene_.options(), frame, cache_);
    if (!built) return runtime::reject("load_set", built.error().message);
    for (const auto& [id, n] : scene_.nodes())
      if (!built->find(id)) load_removed_.insert(id);
    scene_ = std::move(*built);
    STUDIO_LOG(info, kLog) << "loaded " << path << ": " << scene_.nodes().size() << " nodes, "
                           << scene_.animations().size() << " animations at frame " << frame;
    return {};
  }

  // Once per wake: the studio clock's tick, then persist (if commands were accepted) and
  // publish what changed.
  void flush(Clock::time_point now) {
    if (options_.clock_source == ClockSource::studio && now >= next_tick_) tick(now);
    if (first_) {
      publish_all();
      first_ = false;
    }
    if (accepted_since_persist_) {
      accepted_since_persist_ = false;
      unpersisted_ = true;
      publish(/*persist_first=*/true);
    } else if (scene_.has_changes()) {
      unpersisted_ = true;
      publish(/*persist_first=*/false);
    }
    // Skipped command ids are either malformed samples (dropped by the validator before the
    // handler sees them) or lost ones.
    const uint64_t malformed = malformed_->value();
    if (skipped_ > malformed + lost_->value()) lost_->add(skipped_ - malformed - lost_->value());
    if (rejected_->value() != rejected_published_) state_dirty_ = true;  // malformed samples too
    if (handled_ || state_dirty_) publish_state();
    if (handled_ && newest_capture_ns_ > 0)
      loop_.completed(uint64_t(std::max<int64_t>(0, scene_.frame())), newest_capture_ns_);
    handled_ = false;
    newest_capture_ns_ = 0;
  }

  void tick(Clock::time_point now) {
    const int64_t real = realtime_ns();
    const int64_t frame = options_.frame_at(real);
    if (frame >= 0 && frame != last_tick_) {
      if (auto ok = scene_.apply(Command{frame, Tick{}}); ok) {
        ticks_->add();
        state_dirty_ = true;
        unpersisted_ = true;
      }
      last_tick_ = frame;
    }
    // Next frame boundary on the realtime clock, mapped onto the steady clock.
    const int64_t next_ns =
        options_.epoch_ns + (std::max<int64_t>(frame, -1) + 1) * options_.period_ns;
    next_tick_ = now + std::chrono::nanoseconds(std::max<int64_t>(next_ns - real, 0));
  }

  // The write-ahead copy now (before anything is published), the durable one by the syncer.
  void persist() {
    if (options_.state_dir.empty()) return;
    // What may be on the wire once the pending changes are out: the published nodes, the
    // updated ones, and the removed ones until their dispose has gone out.
    std::set<NodeId> on_wire = published_;
    for (const auto& [id, n] : scene_.nodes()) on_wire.insert(id);
    auto bytes = std::make_shared<const std::vector<std::uint8_t>>(
        encode_state(scene_, on_wire, ++sequence_));
    if (auto ok = wal_->write(*bytes, sequence_); !ok) {
      persist_failed(ok.error());
      return;
    }
    persists_->add();
    unpersisted_ = false;
    {
      std::lock_guard lock(sync_mutex_);
      to_sync_ = std::move(bytes);
    }
    sync_wake_.notify_one();
  }

  void persist_failed(const Error& e) {
    persist_failures_->add();
    if (!persist_failing_.exchange(true))
      STUDIO_LOG(error, kLog) << "persisting failed: " << e.message;
  }

  // The syncer thread: the newest state written durably (tmp, fsync, rename, fsync the
  // directory), at most once per persist_interval; states that arrive meanwhile are coalesced.
  void sync_loop() {
    while (loop_.running()) {
      std::shared_ptr<const std::vector<std::uint8_t>> bytes;
      {
        std::unique_lock lock(sync_mutex_);
        sync_wake_.wait(lock, [&] { return to_sync_ || !loop_.running(); });
        bytes = std::move(to_sync_);
      }
      if (!bytes) continue;
      sync(*bytes);
      // At most one durable write per persist_interval: every fsync forces a journal commit
      // that the loop's write-ahead writes would otherwise queue behind (the latency tail).
      std::unique_lock lock(sync_mutex_);
      sync_wake_.wait_for(lock, std::chrono::duration<double>(options_.persist_interval),
                          [&] { return !loop_.running(); });
    }
  }
  void sync(const std::vector<std::uint8_t>& bytes) {
    if (auto ok = write_durable(options_.state_dir, bytes); !ok) {
      persist_failed(ok.error());
      return;
    }
    syncs_->add();
    if (persist_failing_.exchange(false)) STUDIO_LOG(info, kLog) << "persisting works again";
  }

  void publish(bool persist_first) {
    if (persist_first) persist();
    const ChangeSet changes = scene_.take_changes();
    for (const NodeId& id : changes.updated) write(*scene_.find(id));
    for (const NodeId& id : changes.removed) dispose(id);
    for (const NodeId& id : load_removed_)
      if (!scene_.find(id)) dispose(id);
    load_removed_.clear();
  }

  // Start: the whole scene, and a dispose for every node the persisted state says was on the
  // wire but the scene no longer has.
  void publish_all() {
    (void)scene_.take_changes();
    std::set<NodeId> gone = published_;
    for (const auto& [id, n] : scene_.nodes()) {
      gone.erase(id);
      write(n);
    }
    for (const NodeId& id : gone) dispose(id);
    if (!gone.empty())
      STUDIO_LOG(info, kLog) << "disposed " << gone.size()
                             << " node(s) the persisted state no longer has";
    state_dirty_ = true;
    if (!gone.empty()) persist();  // the published set without them
  }

  void write(const scene::Node& n) {
    auto ok = wire::from_core(n, *node_sample_);
    if (ok) {
      node_sample_->capture_ns = options_.epoch_ns + n.frame * options_.period_ns;
      ok = nodes_out_->write(*node_sample_);
    }
    if (!ok) {
      publish_failures_->add();
      STUDIO_LOG(warn, kLog) << "node '" << n.id << "' not published: " << ok.error().message;
      return;
    }
    published_.insert(n.id);
  }

  void dispose(const NodeId& id) {
    if (id.size() > 63) return;  // never published (from_core refuses such ids)
    wire::set(key_sample_->node_id, id);
    if (auto ok = nodes_out_->dispose(*key_sample_); !ok) {
      publish_failures_->add();
      STUDIO_LOG(warn, kLog) << "node '" << id << "' not disposed: " << ok.error().message;
      return;
    }
    disposed_->add();
    published_.erase(id);
  }

  void publish_state() {
    studio_SceneState& s = *state_sample_;
    wire::set(s.instance, instance_.substr(0, 63));
    s.frame = uint64_t(std::max<int64_t>(0, scene_.frame()));
    s.capture_ns = realtime_ns();
    s.state_hash = scene_.state_hash();
    s.nodes_hash = scene_.nodes_hash();
    s.node_count = uint32_t(scene_.nodes().size());
    s.animation_count = uint32_t(scene_.animations().size());
    s.commands_accepted = accepted_->value();
    s.commands_rejected = rejected_published_ = rejected_->value();
    s.commands_lost = lost_->value();
    wire::set(s.last_sender, last_sender_.substr(0, 63));
    s.last_command_id = last_id_;
    s.last_accepted = last_accepted_;
    wire::set(s.last_error, last_error_.substr(0, 255));
    (void)state_out_->write(s);
    state_dirty_ = false;
  }

  NodeOptions options_;
  std::optional<WriteAheadLog> wal_;  // with state_dir
  Scene scene_;
  scene_assets::AssetCache cache_;  // assets of loaded sets, loaded once each
  std::set<NodeId> published_;      // alive instances this server wrote
  std::set<NodeId> load_removed_;   // nodes a LOAD_SET replaced away, disposed at the next publish
  std::string instance_;
  Clock::time_point next_tick_ = Clock::time_point::min();
  int64_t last_tick_ = std::numeric_limits<int64_t>::min();
  bool first_ = true, handled_ = false, state_dirty_ = true;
  bool accepted_since_persist_ = false, unpersisted_ = false;
  std::atomic<bool> persist_failing_{false};
  std::uint64_t sequence_ = 0;  // of the last state written
  std::mutex sync_mutex_;
  std::condition_variable sync_wake_;
  std::shared_ptr<const std::vector<std::uint8_t>> to_sync_;  // newest state not yet durable
  int64_t newest_capture_ns_ = 0;
  std::map<std::string, uint64_t> next_id_;  // per sender: the command_id expected next
  std::string last_sender_, last_error_;
  uint64_t last_id_ = 0, rejected_published_ = 0, skipped_ = 0;
  bool last_accepted_ = true;
  wire::Owned<studio_SceneNode> node_sample_{}, key_sample_{};
  wire::Owned<studio_SceneState> state_sample_{};
  runtime::Output<studio_SceneNode>* nodes_out_ = nullptr;
  runtime::Output<studio_SceneState>* state_out_ = nullptr;
  runtime::Input<studio_SceneCommand>* commands_ = nullptr;
  runtime::Counter *accepted_ = nullptr, *rejected_ = nullptr, *lost_ = nullptr, *ticks_ = nullptr,
                   *disposed_ = nullptr, *persists_ = nullptr, *persist_failures_ = nullptr,
                   *publish_failures_ = nullptr, *malformed_ = nullptr, *syncs_ = nullptr;
  runtime::ServiceLoop loop_;  // last: stopped before the state above goes
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_scene_server(NodeOptions options,
                                                           runtime::NodeContext& context) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  PersistedState state{Scene(SceneOptions{options.frame_period()}), {}, 0};
  if (auto ok = state.scene.options().validate(); !ok) return std::unexpected(ok.error());
  scene_assets::AssetCache cache;
  bool resumed = false;
  if (!options.state_dir.empty()) {
    auto loaded = read_state(options.state_dir);
    if (!loaded) return std::unexpected(loaded.error());
    if (*loaded) {
      if (!(*loaded)->warning.empty()) STUDIO_LOG(warn, kLog) << (*loaded)->warning;
      if (!((*loaded)->state.scene.options() == state.scene.options()))
        return fail((*loaded)->path + ": persisted with frame period " +
                    std::to_string((*loaded)->state.scene.options().frame_period) +
                    " s, the config's clock says " + std::to_string(options.frame_period()) +
                    " s (move the file away to start empty)");
      const std::string path = (*loaded)->path;
      state = std::move((*loaded)->state);
      resumed = true;
      STUDIO_LOG(info, kLog) << "resumed " << state.scene.nodes().size() << " nodes, "
                             << state.scene.animations().size() << " animations at frame "
                             << state.scene.frame() << " from " << path;
    }
  }
  // First start: the configured scene, built at the studio frame now.
  if (!resumed && !options.scene_file.empty()) {
    const int64_t frame = options.clock_source == ClockSource::studio
                              ? std::max<int64_t>(0, options.frame_at(realtime_ns()))
                              : 0;
    auto built = load_scene_file(options.scene_file, state.scene.options(), frame, cache);
    if (!built) return std::unexpected(built.error());
    state.scene = std::move(*built);
    STUDIO_LOG(info, kLog) << "loaded " << options.scene_file << ": " << state.scene.nodes().size()
                           << " nodes, " << state.scene.animations().size() << " animations";
  }
  std::optional<WriteAheadLog> wal;
  if (!options.state_dir.empty()) {
    auto opened = WriteAheadLog::open(options.state_dir);
    if (!opened) return std::unexpected(opened.error());
    wal.emplace(std::move(*opened));
  }
  return std::make_unique<SceneServer>(std::move(options), std::move(state), std::move(cache),
                                       std::move(wal), context);
}

runtime::ServiceDefinition service_definition() {
  runtime::ServiceDefinition d;
  d.name = "scene";
  d.summary =
      "Virtual scene server (TCSVT 2004 V): holds the master scene graph, applies\n"
      "studio/scene/command (SceneCommand) with validation, evaluates animations on the studio\n"
      "clock, publishes every node as a keyed studio/scene/node instance (disposed when removed)\n"
      "and its state on studio/scene/state, and persists the scene atomically in state_dir.";
  d.config_help = kConfigHelp;
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& context) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = read_node_options(config);
    if (!options) return std::unexpected(options.error());
    return make_scene_server(std::move(*options), context);
  };
  return d;
}

}  // namespace studio::scene::node

#include "keyer_node.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "core/clock.h"
#include "core/log.h"
#include "image_io.h"
#include "kept_plates.h"
#include "keyer/keyer.h"
#include "keyer_yaml.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "wire/sample.h"
#include "yaml_io/options.h"

namespace studio::keyer {
namespace {

constexpr const char* kLog = "keyer";
using SteadyClock = std::chrono::steady_clock;

// One camera: its keyer, the newest frame waiting to be keyed, and the keying thread's buffers.
struct Slot {
  std::string id;
  std::optional<Keyer> keyer;  // touched only by the keying thread that holds `busy`
  // Guarded by KeyerNode::mutex_.
  std::vector<uint8_t> pending;
  int pending_w = 0, pending_h = 0;
  uint64_t pending_frame = 0;
  uint64_t last_frame_in = 0;  // newest frame number received (0: none yet)
  int64_t pending_capture_ns = 0;
  bool has_pending = false;
  bool busy = false;
  int plate_request = -1;  // -1 none, 0 clear, N: average the next N frames into a new plate
  // Owned by the keying thread holding `busy`.
  std::vector<uint8_t> work;
  int plate_remaining = 0;
  bool warned_no_plate = false;
  RunMask mask;
  wire::Owned<studio_AlphaMask> sample;
};

class KeyerNode : public runtime::Node {
 public:
  KeyerNode(KeyerNodeOptions options, runtime::NodeContext& ctx)
      : options_(std::move(options)),
        participant_(ctx.participant),
        metrics_(ctx.metrics),
        images_in_(ctx.metrics.counter("images_in")),
        masks_published_(ctx.metrics.counter("masks_published")),
        rejected_(ctx.metrics.counter("images_rejected")),
        rejected_malformed_(ctx.metrics.counter("rejected_malformed")),
        rejected_format_(ctx.metrics.counter("rejected_format")),
        rejected_keyer_(ctx.metrics.counter("rejected_keyer")),
        rejected_cameras_(ctx.metrics.counter("rejected_cameras")),
        images_ignored_(ctx.metrics.counter("images_ignored")),
        dropped_(ctx.metrics.counter("frames_dropped")),
        missed_(ctx.metrics.counter("frames_missed")),
        unkeyed_(ctx.metrics.counter("frames_unkeyed")),
        plates_captured_(ctx.metrics.counter("plates_captured")),
        plate_saves_failed_(ctx.metrics.counter("plate_saves_failed")),
        controls_rejected_(ctx.metrics.counter("controls_rejected")) {}

  ~KeyerNode() override { stop(); }

  // Creates the configured cameras' keyers (plates applied), so plate errors fail the start.
  Expected<void> init() {
    if (auto r = kept_.prepare(); !r) return r;
    for (const std::string& id : options_.cameras)
      if (auto s = add_slot(id); !s) return std::unexpected(s.error());
    return {};
  }

  Expected<void> start() override {
    auto io = wire::gather([](auto&&... e) { return Io{std::move(e)...}; },
                           wire::Subscription<studio_CameraImage>::create(participant_),
                           wire::Subscription<studio_CameraControl>::create(participant_),
                           wire::Publication<studio_AlphaMask>::create(participant_),
                           wire::WaitSet::create(participant_),
                           wire::GuardCondition::create(participant_));
    if (!io) return std::unexpected(io.error());
    if (auto r = io->waitset.attach(*io->images, 1); !r) return std::unexpected(r.error());
    if (auto r = io->waitset.attach(*io->controls, 2); !r) return std::unexpected(r.error());
    if (auto r = io->waitset.attach(io->guard, 3); !r) return std::unexpected(r.error());
    io_.emplace(std::move(*io));
    running_ = true;
    reader_ = std::thread([this] { read_loop(); });
    for (int i = 0; i < options_.threads; ++i) workers_.emplace_back([this] { key_loop(); });
    STUDIO_LOG(info, kLog) << "keying "
                           << (options_.cameras.empty() ? "every camera" : "the configured cameras")
                           << " with the " << key_mode_name(options_.keyer.mode) << " key ("
                           << Keyer::kernel_name() << " kernel, " << options_.threads
                           << " thread(s))";
    return {};
  }

  void stop() override {
    if (!running_.exchange(false)) return;
    io_->guard.trigger();
    { std::lock_guard lock(mutex_); }  // a keying thread between its check and its wait sees it
    cv_.notify_all();
    if (reader_.joinable()) reader_.join();
    for (auto& w : workers_)
      if (w.joinable()) w.join();
    workers_.clear();
    io_.reset();
  }

  runtime::NodeHealth health() override {
    runtime::NodeHealth h;
    h.frame = last_frame_.load();
    h.capture_ns = last_capture_ns_.load();
    const auto now = SteadyClock::now();
    const double dt = std::chrono::duration<double>(now - last_health_).count();
    const uint64_t in = images_in_.value(), out = masks_published_.value(),
                   unkeyed = unkeyed_.value();
    if (dt > 0) {
      h.input_hz = double(in - last_in_) / dt;
      h.output_hz = double(out - last_out_) / dt;
    }
    // Degraded while frames go unkeyed for want of a clean plate.
    h.degraded = unkeyed > last_unkeyed_;
    last_health_ = now;
    last_in_ = in;
    last_out_ = out;
    last_unkeyed_ = unkeyed;
    return h;
  }

 private:
  struct Io {
    wire::Subscription<studio_CameraImage> images;
    wire::Subscription<studio_CameraControl> controls;
    wire::Publication<studio_AlphaMask> masks;
    wire::WaitSet waitset;
    wire::GuardCondition guard;
  };

  // New camera slot with its keyer (and plate from the config). Caller holds mutex_ once running.
  Expected<Slot*> add_slot(const std::string& id) {
    auto keyer = Keyer::create(options_.keyer);
    if (!keyer) return std::unexpected(keyer.error());
    auto slot = std::make_unique<Slot>();
    slot->id = id;
    slot->keyer.emplace(std::move(*keyer));
    if (auto p = options_.plates.find(id); p != options_.plates.end()) {
      if (auto r = slot->keyer->capture_plate(p->second.view()); !r)
        return fail("plate of " + id + ": " + r.error().message);
    } else if (auto kept = kept_.load(id, *slot->keyer); !kept) {
      // Unreadable: the camera waits for a new plate.
      STUDIO_LOG(warn, kLog) << id << ": kept plate not used: " << kept.error().message;
    } else if (*kept) {
      STUDIO_LOG(info, kLog) << id << ": clean plate from " << kept_.path(id);
    }
    wire::set(slot->sample->camera_id, id);
    slots_.push_back(std::move(slot));
    return slots_.back().get();
  }

  Slot* find_slot(std::string_view id) {
    for (auto& s : slots_)
      if (s->id == id) return s.get();
    return nullptr;
  }

  // The slot of `id`, created when keying every camera; nullptr when the camera is not ours
  // (counted by the caller) or over max_cameras (counted here). Caller holds mutex_.
  Slot* slot_for(std::string_view id, bool& ignored) {
    ignored = false;
    if (Slot* s = find_slot(id)) return s;
    if (!options_.cameras.empty()) {
      ignored = true;
      return nullptr;
    }
    if (int(slots_.size()) >= options_.max_cameras) {
      rejected_cameras_.add();
      rejected_.add();
      if (!warned_max_cameras_) {
        STUDIO_LOG(warn, kLog) << "camera " << id << " rejected: already keying max_cameras "
                               << options_.max_cameras;
      }
      warned_max_cameras_ = true;
      return nullptr;
    }
    auto s = add_slot(std::string(id));
    if (!s) {  // cannot happen for options that validated; count rather than fail
      rejected_keyer_.add();
      rejected_.add();
      return nullptr;
    }
    STUDIO_LOG(info, kLog) << "keying camera " << id;
    return *s;
  }

  void read_loop() {
    std::vector<uint8_t> incoming;
    while (running_) {
      io_->waitset.wait(std::chrono::milliseconds(200));
      if (!running_) break;
      io_->controls->visit([&](const studio_CameraControl& c, const wire::SampleMeta& meta) {
        if (meta.valid_data) handle_control(c);
      });
      io_->images->visit([&](const studio_CameraImage& s, const wire::SampleMeta& meta) {
        if (!meta.valid_data) return;
        images_in_.add();
        if (s.format != studio_IMAGE_RGB8) {
          rejected_format_.add();
          rejected_.add();
          if (!warned_format_) {
            STUDIO_LOG(warn, kLog)
                << "camera " << s.camera_id << ": "
                << (s.format == studio_IMAGE_JPEG ? "JPEG" : "MONO8")
                << " image rejected: the keyer needs raw RGB8 (capture: image.raw: true)";
          }
          warned_format_ = true;
          return;
        }
        Slot* slot = nullptr;
        {
          std::lock_guard lock(mutex_);
          bool ignored = false;
          slot = slot_for(s.camera_id, ignored);
          if (!slot) {
            if (ignored) images_ignored_.add();
            return;
          }
        }
        // Copied outside the lock (slots are never removed); the validator checked
        // data.size() == 3 * width * height.
        const auto data = wire::view(s.data);
        incoming.assign(data.begin(), data.end());
        std::lock_guard lock(mutex_);
        if (slot->has_pending) dropped_.add();  // the previous frame was never keyed
        if (slot->last_frame_in != 0 && s.frame > slot->last_frame_in + 1)
          missed_.add(std::min<uint64_t>(s.frame - slot->last_frame_in - 1, 1000));
        if (s.frame > slot->last_frame_in) slot->last_frame_in = s.frame;
        slot->pending.swap(incoming);
        slot->pending_w = int(s.width);
        slot->pending_h = int(s.height);
        slot->pending_frame = s.frame;
        slot->pending_capture_ns = s.capture_ns;
        slot->has_pending = true;
        cv_.notify_one();
      });
      sync_wire_rejections();
    }
  }

  void handle_control(const studio_CameraControl& c) {
    if (std::string_view(c.feature) != kPlateControl) return;  // a camera feature, for capture
    if (!valid_plate_request(c.value)) {
      controls_rejected_.add();
      STUDIO_LOG(warn, kLog) << c.camera_id << ": " << kPlateControl << " " << c.value
                             << " rejected: expected 0 (clear) or a frame count 1.."
                             << kMaxPlateFrames;
      return;
    }
    std::lock_guard lock(mutex_);
    bool ignored = false;
    Slot* slot = slot_for(c.camera_id, ignored);
    if (!slot) return;  // another keyer node's camera (or over max_cameras, counted there)
    slot->plate_request = int(c.value);
    STUDIO_LOG(info, kLog) << c.camera_id << ": "
                           << (c.value == 0 ? std::string("clean plate cleared")
                                            : "capturing a clean plate from the next " +
                                                  std::to_string(int(c.value)) + " frame(s)");
  }

  // Mirrors the wire validator's refusals into the service counters.
  void sync_wire_rejections() {
    const uint64_t total = io_->images->rejected().total();
    if (total > seen_malformed_) {
      rejected_malformed_.add(total - seen_malformed_);
      rejected_.add(total - seen_malformed_);
      seen_malformed_ = total;
    }
  }

  void key_loop() {
    std::size_t next = 0;  // round-robin start, so no camera starves
    while (true) {
      Slot* slot = nullptr;
      int plate_request = -1;
      int w = 0, h = 0;
      uint64_t frame = 0;
      int64_t capture_ns = 0;
      {
        std::unique_lock lock(mutex_);
        cv_.wait(lock, [&] {
          if (!running_) return true;
          for (std::size_t k = 0; k < slots_.size(); ++k) {
            Slot* s = slots_[(next + k) % slots_.size()].get();
            if (s->has_pending && !s->busy) {
              slot = s;
              next = (next + k + 1) % slots_.size();
              return true;
            }
          }
          return false;
        });
        if (!running_) return;
        slot->work.swap(slot->pending);
        slot->has_pending = false;
        slot->busy = true;
        plate_request = std::exchange(slot->plate_request, -1);
        w = slot->pending_w;
        h = slot->pending_h;
        frame = slot->pending_frame;
        capture_ns = slot->pending_capture_ns;
      }
      process(*slot, plate_request, w, h, frame, capture_ns);
      {
        std::lock_guard lock(mutex_);
        slot->busy = false;
      }
      cv_.notify_all();  // the camera may have a newer frame waiting
    }
  }

  void process(Slot& slot, int plate_request, int w, int h, uint64_t frame, int64_t capture_ns) {
    const ImageView<const Rgb8> image(reinterpret_cast<const Rgb8*>(slot.work.data()), w, h);
    Keyer& keyer = *slot.keyer;
    if (plate_request >= 0) {
      keyer.clear_plate();
      slot.plate_remaining = plate_request;
      slot.warned_no_plate = false;
      if (plate_request == 0) kept_.remove(slot.id);
    }
    if (slot.plate_remaining > 0) {
      if (auto r = keyer.capture_plate(image); !r) {
        rejected_keyer_.add();
        rejected_.add();
        STUDIO_LOG(warn, kLog) << slot.id << ": plate frame " << frame << ": " << r.error().message;
        return;
      }
      if (--slot.plate_remaining == 0) {
        plates_captured_.add();
        STUDIO_LOG(info, kLog) << slot.id << ": clean plate captured (" << keyer.plate_frames()
                               << " frames, " << w << "x" << h << ")";
        if (auto r = kept_.save(slot.id, keyer); !r) {
          plate_saves_failed_.add();
          STUDIO_LOG(warn, kLog) << slot.id << ": clean plate not kept: " << r.error().message;
        }
      }
      return;
    }
    if (auto r = keyer.key(image, slot.mask); !r) {
      if (options_.keyer.mode == KeyMode::kDifference && !keyer.has_plate()) {
        unkeyed_.add();
        if (!slot.warned_no_plate) {
          STUDIO_LOG(warn, kLog) << slot.id << ": no clean plate yet (send CameraControl "
                                 << kPlateControl
                                 << " N, or give plates: in the config); frames are not keyed";
        }
        slot.warned_no_plate = true;
      } else {
        rejected_keyer_.add();
        rejected_.add();
        STUDIO_LOG(debug, kLog) << slot.id << ": frame " << frame << ": " << r.error().message;
      }
      return;
    }
    studio_AlphaMask& s = *slot.sample;
    s.frame = frame;
    s.capture_ns = capture_ns;
    wire::from_core(slot.mask, studio_MASK_CODEC, s);
    if (auto r = io_->masks->write(s); !r) {
      STUDIO_LOG(warn, kLog) << slot.id << ": " << r.error().message;
      return;
    }
    masks_published_.add();
    metrics_.latency().record(realtime_ns() - capture_ns);
    last_frame_ = frame;
    last_capture_ns_ = capture_ns;
  }

  KeyerNodeOptions options_;
  const wire::Participant& participant_;
  runtime::Metrics& metrics_;
  runtime::Counter &images_in_, &masks_published_, &rejected_, &rejected_malformed_,
      &rejected_format_, &rejected_keyer_, &rejected_cameras_, &images_ignored_, &dropped_,
      &missed_, &unkeyed_, &plates_captured_, &plate_saves_failed_, &controls_rejected_;
  KeptPlates kept_{options_.plate_dir};
  std::optional<Io> io_;
  std::atomic<bool> running_{false};
  std::thread reader_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::unique_ptr<Slot>> slots_;  // guarded by mutex_; slots are never removed
  bool warned_format_ = false, warned_max_cameras_ = false;  // reader thread
  uint64_t seen_malformed_ = 0;                              // reader thread
  std::atomic<uint64_t> last_frame_{0};
  std::atomic<int64_t> last_capture_ns_{0};
  SteadyClock::time_point last_health_ = SteadyClock::now();
  uint64_t last_in_ = 0, last_out_ = 0, last_unkeyed_ = 0;
};

std::string resolve(const yaml::Node& n, const std::string& path) {
  if (path.empty() || path.front() == '/') return path;
  return (std::filesystem::path(n.file()).parent_path() / path).string();
}

template <class T>
Expected<void> read_int(yaml::MapReader& config, std::string_view key, T& out, int lo, int hi) {
  auto n = config.optional(key);
  if (!n) return {};
  yaml::Constraints c;
  c.min = lo;
  c.max = hi;
  return yaml::read_value(*n, out, c);
}

// The node's keys of the service config (see keyer_node.h).
Expected<KeyerNodeOptions> read_config(yaml::MapReader& config) {
  KeyerNodeOptions o;
  if (auto n = config.optional("keyer")) {
    Expected<KeyerOptions> k;
    if (n->is_null()) {
      k = KeyerOptions{};  // `keyer:` with nothing under it: the defaults
    } else if (n->is_map()) {
      k = load_keyer_options(n->file());  // reads this file's `keyer:` section
    } else if (n->is_scalar()) {
      auto path = n->as_string();
      if (!path) return std::unexpected(path.error());
      k = load_keyer_options(resolve(*n, *path));
    } else {
      return n->fail("expected the keyer options (a mapping) or the path of a keyer.yaml");
    }
    if (!k) return std::unexpected(k.error());
    o.keyer = *k;
  }
  if (auto n = config.optional("cameras")) {
    if (auto r = yaml::read_value(*n, o.cameras, {}); !r) return std::unexpected(r.error());
    if (o.cameras.empty())
      return n->fail("expected at least one camera id (leave the key out to key every camera)");
    std::set<std::string> seen;
    for (const auto& id : o.cameras) {
      if (id.empty() || id.size() > 63) return n->fail("camera ids have 1..63 characters");
      if (!seen.insert(id).second) return n->fail("duplicate camera id " + id);
    }
  }
  if (auto r = read_int(config, "max_cameras", o.max_cameras, 1, 64); !r)
    return std::unexpected(r.error());
  if (auto r = read_int(config, "threads", o.threads, 1, 16); !r) return std::unexpected(r.error());
  if (auto n = config.optional("plate_dir")) {
    if (o.keyer.mode != KeyMode::kDifference)
      return n->fail("clean plates need the difference key (keyer.key)");
    auto path = n->as_string();
    if (!path) return std::unexpected(path.error());
    if (path->empty()) return n->fail("expected a folder");
    o.plate_dir = resolve(*n, *path);
  }
  if (auto n = config.optional("plates")) {
    if (o.keyer.mode != KeyMode::kDifference)
      return n->fail("clean plates need the difference key (keyer.key)");
    auto entries = n->entries();
    if (!entries) return std::unexpected(entries.error());
    for (const auto& [id, file] : *entries) {
      if (!o.cameras.empty() &&
          std::find(o.cameras.begin(), o.cameras.end(), id) == o.cameras.end())
        return file.fail("camera " + id + " is not in cameras");
      auto path = file.as_string();
      if (!path) return std::unexpected(path.error());
      auto image = read_rgb(resolve(file, *path));
      if (!image) return file.fail(image.error().message);
      o.plates.emplace(id, std::move(*image));
    }
  }
  return o;
}

}  // namespace

Expected<void> KeyerNodeOptions::validate() const {
  if (auto k = keyer.validate(); !k) return k;
  if (max_cameras < 1 || max_cameras > 64) return fail("max_cameras: must be in [1, 64]");
  if (threads < 1 || threads > 16) return fail("threads: must be in [1, 16]");
  if (!plates.empty() && keyer.mode != KeyMode::kDifference)
    return fail("plates: need the difference key");
  if (!plate_dir.empty() && keyer.mode != KeyMode::kDifference)
    return fail("plate_dir: needs the difference key");
  return {};
}

Expected<std::unique_ptr<runtime::Node>> make_keyer_node(KeyerNodeOptions options,
                                                         runtime::NodeContext& context) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  auto node = std::make_unique<KeyerNode>(std::move(options), context);
  if (auto r = node->init(); !r) return std::unexpected(r.error());
  return std::unique_ptr<runtime::Node>(std::move(node));
}

runtime::ServiceDefinition keyer_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "keyer";
  d.summary =
      "Standalone keyer: raw RGB8 camera images in (studio/camera/image), masks out "
      "(studio/camera/mask).";
  d.config_help =
      "  keyer: {...} | FILE       keyer options (keyer.example.yaml): this file's keyer: section "
      "or a file\n"
      "  cameras: [cam0, ...]      camera ids to key (default: every camera seen)\n"
      "  max_cameras: 16           cameras keyed at most when keying every camera seen (1..64)\n"
      "  threads: 1                keying threads (1..16)\n"
      "  plates: {cam0: FILE}      clean plates for the difference key (PNG/JPEG, frame size)\n"
      "  plate_dir: DIR            keep plates captured on command as DIR/<camera>.png, load at start\n"
      "Clean plate on command: CameraControl feature KeyerPlate, value N averages the next N "
      "frames\n"
      "(0 clears). Only the newest frame per camera waits; older ones are dropped and counted.\n";
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = read_config(config);
    if (!options) return std::unexpected(options.error());
    return make_keyer_node(std::move(*options), ctx);
  };
  return d;
}

}  // namespace studio::keyer

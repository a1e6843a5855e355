#include "keyer_node.h"

#include <condition_variable>
#include <mutex>
#include <optional>

#include "core/log.h"
#include "keyer/config/image_io.h"
#include "keyer/config/kept_plates.h"
#include "keyer/plate_keyer.h"
#include "runtime/service_loop.h"
#include "wire/convert.h"
#include "wire/sample.h"

namespace studio::keyer {
namespace {

constexpr const char* kLog = "keyer";

// One camera: its keyer, the newest frame waiting to be keyed, and the keying thread's buffers.
struct Slot {
  std::string id;
  std::optional<PlateKeyer> keyer;  // keyed only by the keying thread that holds `busy`
  // Guarded by KeyerNode::mutex_.
  std::vector<uint8_t> pending;
  int pending_w = 0, pending_h = 0;
  uint64_t pending_frame = 0;
  uint64_t last_frame_in = 0;  // newest frame number received (0: none yet)
  int64_t pending_capture_ns = 0;
  bool has_pending = false;
  bool busy = false;
  // Owned by the keying thread holding `busy`.
  std::vector<uint8_t> work;
  int work_w = 0, work_h = 0;
  uint64_t work_frame = 0;
  int64_t work_capture_ns = 0;
  RunMask mask;
  wire::Owned<studio_AlphaMask> sample;
};

class KeyerNode : public runtime::Node {
 public:
  KeyerNode(KeyerNodeOptions options, runtime::NodeContext& ctx)
      : options_(std::move(options)), kept_(options_.plate_dir), loop_(ctx, kLog) {
    masks_ = &loop_.output<studio_AlphaMask>({.counter = "masks_published"});
    loop_.input<studio_CameraControl>(
        {.received = "controls_in",
         .rejected = "controls_rejected",
         .reason_prefix = "controls_rejected_",
         .rate = false},
        [this](const studio_CameraControl& c, const wire::SampleMeta&) { return on_control(c); });
    images_ = &loop_.input<studio_CameraImage>(
        {.received = "images_in", .rejected = "images_rejected"},
        [this](const studio_CameraImage& s, const wire::SampleMeta&) { return on_image(s); });
    for (const char* name : {"images_ignored", "frames_dropped", "frames_missed", "frames_unkeyed",
                             "plates_captured", "plate_saves_failed"})
      counters_.push_back(&loop_.counter(name));
    for (int i = 0; i < options_.threads; ++i)
      loop_.thread(
          "key" + std::to_string(i), [this] { key_loop(); },
          [this] {
            std::lock_guard lock(mutex_);
            cv_.notify_all();
          });
  }
  ~KeyerNode() override { stop(); }

  // Reads the plate files and creates the configured cameras' keyers, so errors fail the start.
  Expected<void> init() {
    if (auto r = kept_.prepare(); !r) return r;
    for (const auto& [id, file] : options_.plates) {
      auto image = read_rgb(file);
      if (!image) return fail("plates: " + id + ": " + image.error().message);
      plates_.emplace(id, std::move(*image));
    }
    for (const std::string& id : options_.cameras)
      if (auto s = add_slot(id); !s) return std::unexpected(s.error());
    return {};
  }

  Expected<void> start() override {
    if (auto r = loop_.start(); !r) return r;
    STUDIO_LOG(info, kLog) << "keying "
                           << (options_.cameras.empty() ? "every camera" : "the configured cameras")
                           << " with the " << key_mode_name(options_.keyer.mode) << " key ("
                           << Keyer::kernel_name() << " kernel, " << options_.threads
                           << " thread(s))";
    return {};
  }
  void stop() override { loop_.stop(); }
  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    // Degraded while frames go unkeyed for want of a clean plate.
    const uint64_t unkeyed = count(kUnkeyed).value();
    h.degraded = unkeyed > last_unkeyed_;
    last_unkeyed_ = unkeyed;
    return h;
  }

 private:
  enum CounterIndex { kIgnored, kDropped, kMissed, kUnkeyed, kPlatesCaptured, kSavesFailed };
  runtime::Counter& count(CounterIndex i) { return *counters_[i]; }

  // New camera slot with its keyer (and its plate). Caller holds mutex_ once running.
  Expected<Slot*> add_slot(const std::string& id) {
    auto keyer = Keyer::create(options_.keyer);
    if (!keyer) return std::unexpected(keyer.error());
    auto slot = std::make_unique<Slot>();
    slot->id = id;
    slot->keyer.emplace(std::move(*keyer));
    if (auto p = plates_.find(id); p != plates_.end()) {
      if (auto r = slot->keyer->keyer().capture_plate(p->second.view()); !r)
        return fail("plate of " + id + ": " + r.error().message);
    } else {
      kept_.restore(id, slot->keyer->keyer(), kLog);
    }
    wire::set(slot->sample->camera_id, id);
    slots_.push_back(std::move(slot));
    return slots_.back().get();
  }

  // The slot of `id`, created when keying every camera; nullptr when the camera is not ours
  // (`ignored`) or over max_cameras (a rejection, counted here). Caller holds mutex_.
  Slot* slot_for(std::string_view id, bool& ignored) {
    ignored = false;
    for (auto& s : slots_)
      if (s->id == id) return s.get();
    if (!options_.cameras.empty()) {
      ignored = true;
      return nullptr;
    }
    if (int(slots_.size()) >= options_.max_cameras) {
      images_->reject({"cameras", "camera " + std::string(id) + ": already keying max_cameras " +
                                      std::to_string(options_.max_cameras)});
      return nullptr;
    }
    auto s = add_slot(std::string(id));
    if (!s) {  // cannot happen for options that validated; count rather than fail
      images_->reject({"keyer", s.error().message});
      return nullptr;
    }
    STUDIO_LOG(info, kLog) << "keying camera " << id;
    return *s;
  }

  runtime::Outcome on_control(const studio_CameraControl& c) {
    if (std::string_view(c.feature) != kPlateControl) return {};  // a camera feature, for capture
    if (!valid_plate_request(c.value))
      return runtime::reject("value", std::string(c.camera_id) + ": " + std::string(kPlateControl) +
                                          " " + std::to_string(c.value) +
                                          ": expected 0 (clear) or a frame count 1.." +
                                          std::to_string(kMaxPlateFrames));
    std::lock_guard lock(mutex_);
    bool ignored = false;
    Slot* slot = slot_for(c.camera_id, ignored);
    if (!slot) return {};  // another keyer node's camera (or over max_cameras, counted there)
    slot->keyer->request(int(c.value));
    STUDIO_LOG(info, kLog) << c.camera_id << ": "
                           << (c.value == 0 ? std::string("clean plate cleared")
                                            : "capturing a clean plate from the next " +
                                                  std::to_string(int(c.value)) + " frame(s)");
    return {};
  }

  // Copies an accepted image into its camera's newest-frame slot for a keying thread.
  runtime::Outcome on_image(const studio_CameraImage& s) {
    if (s.format != studio_IMAGE_RGB8)
      return runtime::reject("format", "camera " + std::string(s.camera_id) + ": " +
                                           (s.format == studio_IMAGE_JPEG ? "JPEG" : "MONO8") +
                                           " image rejected: the keyer needs raw RGB8 (capture: "
                                           "image.raw: true)");
    Slot* slot = nullptr;
    {
      std::lock_guard lock(mutex_);
      bool ignored = false;
      slot = slot_for(s.camera_id, ignored);
      if (!slot) {
        if (ignored) count(kIgnored).add();
        return {};
      }
    }
    // Copied outside the lock (slots are never removed); the validator checked
    // data.size() == 3 * width * height.
    const auto data = wire::view(s.data);
    incoming_.assign(data.begin(), data.end());
    std::lock_guard lock(mutex_);
    if (slot->has_pending) count(kDropped).add();  // the previous frame was never keyed
    if (slot->last_frame_in != 0 && s.frame > slot->last_frame_in + 1)
      count(kMissed).add(std::min<uint64_t>(s.frame - slot->last_frame_in - 1, 1000));
    if (s.frame > slot->last_frame_in) slot->last_frame_in = s.frame;
    slot->pending.swap(incoming_);
    slot->pending_w = int(s.width);
    slot->pending_h = int(s.height);
    slot->pending_frame = s.frame;
    slot->pending_capture_ns = s.capture_ns;
    slot->has_pending = true;
    cv_.notify_one();
    return {};
  }

  // The next camera with a frame waiting and no thread keying it (round-robin from `next`, so no
  // camera starves), its frame moved to the work buffers; nullptr when stopping.
  Slot* take_work(std::size_t& next) {
    std::unique_lock lock(mutex_);
    Slot* slot = nullptr;
    cv_.wait(lock, [&] {
      if (!loop_.running()) return true;
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
    if (!loop_.running()) return nullptr;
    slot->work.swap(slot->pending);
    slot->has_pending = false;
    slot->busy = true;
    slot->work_w = slot->pending_w;
    slot->work_h = slot->pending_h;
    slot->work_frame = slot->pending_frame;
    slot->work_capture_ns = slot->pending_capture_ns;
    return slot;
  }

  void key_loop() {
    std::size_t next = 0;
    while (Slot* slot = take_work(next)) {
      process(*slot);
      {
        std::lock_guard lock(mutex_);
        slot->busy = false;
      }
      cv_.notify_all();  // the camera may have a newer frame waiting
    }
  }

  void process(Slot& slot) {
    const ImageView<const Rgb8> image(reinterpret_cast<const Rgb8*>(slot.work.data()), slot.work_w,
                                      slot.work_h);
    const PlateKeyer::Result r = slot.keyer->frame(image, slot.mask);
    if (r.cleared) kept_.remove(slot.id);
    switch (r.step) {
      case PlateKeyer::Step::kPlateFrame:
        return;
      case PlateKeyer::Step::kPlateCaptured:
        count(kPlatesCaptured).add();
        STUDIO_LOG(info, kLog) << slot.id << ": clean plate captured ("
                               << slot.keyer->keyer().plate_frames() << " frames, " << slot.work_w
                               << "x" << slot.work_h << ")";
        if (!kept_.keep(slot.id, slot.keyer->keyer(), kLog)) count(kSavesFailed).add();
        return;
      case PlateKeyer::Step::kNoPlate:
        count(kUnkeyed).add();
        if (r.first)
          STUDIO_LOG(warn, kLog) << slot.id << ": no clean plate yet (send CameraControl "
                                 << kPlateControl
                                 << " N, or give plates: in the config); frames are not keyed";
        return;
      case PlateKeyer::Step::kRefused:
        images_->reject({"keyer", slot.id + ": frame " + std::to_string(slot.work_frame) + ": " +
                                      r.error.message});
        return;
      case PlateKeyer::Step::kKeyed:
        break;
    }
    studio_AlphaMask& s = *slot.sample;
    s.frame = slot.work_frame;
    s.capture_ns = slot.work_capture_ns;
    wire::from_core(slot.mask, studio_MASK_CODEC, s);
    if (masks_->write(s)) loop_.completed(slot.work_frame, slot.work_capture_ns);
  }

  KeyerNodeOptions options_;
  KeptPlates kept_;
  std::map<std::string, Image<Rgb8>> plates_;  // from the plate files, by camera id
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::unique_ptr<Slot>> slots_;  // guarded by mutex_; slots are never removed
  std::vector<uint8_t> incoming_;             // loop thread
  uint64_t last_unkeyed_ = 0;                 // health()
  runtime::Output<studio_AlphaMask>* masks_ = nullptr;
  runtime::Input<studio_CameraImage>* images_ = nullptr;
  std::vector<runtime::Counter*> counters_;  // by CounterIndex
  runtime::ServiceLoop loop_;                // last: stopped before the state above goes
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_keyer_node(KeyerNodeOptions options,
                                                         runtime::NodeContext& context) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  auto node = std::make_unique<KeyerNode>(std::move(options), context);
  if (auto r = node->init(); !r) return std::unexpected(r.error());
  return std::unique_ptr<runtime::Node>(std::move(node));
}

}  // namespace studio::keyer

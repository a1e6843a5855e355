#include "capture_node.h"

#include <algorithm>

#include "camera_worker.h"
#include "image_ring.h"
#include "capture/disk_rate.h"
#include "core/clock.h"
#include "core/log.h"

namespace studio::capture::node {
namespace {

constexpr const char* kLog = "capture";

bool valid_take_name(const std::string& s) {
  if (s.empty() || s == "." || s == ".." || s.size() > 63) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

class CaptureNode : public runtime::Node {
 public:
  CaptureNode(CaptureNodeOptions options, runtime::NodeContext& context)
      : options_(std::move(options)),
        kept_plates_(options_.plate_dir),
        loop_(context, kLog),
        stages_(context.metrics),
        io_{.options = options_,
            .kept_plates = kept_plates_,
            .loop = loop_,
            .masks = loop_.output<studio_AlphaMask>({.counter = "masks_published"}),
            .images = loop_.output<studio_CameraImage>(
                {.counter = "images_published", .rate = !options_.publish_masks}),
            .states =
                loop_.output<studio_CameraState>({.counter = "states_published", .rate = false}),
            .calibrations = loop_.output<studio_CameraCalibration>(
                {.counter = "calibrations_published", .rate = false}),
            .frames_captured = loop_.counter("frames_captured"),
            .frames_recorded = loop_.counter("frames_recorded"),
            .frames_dropped = loop_.counter("frames_dropped"),
            .frames_unkeyed = loop_.counter("frames_unkeyed"),
            .plates_captured = loop_.counter("plates_captured"),
            .plate_saves_failed = loop_.counter("plate_saves_failed"),
            .stages = stages_} {
    loop_.count_as_input(io_.frames_captured);
    loop_.input<studio_CameraControl>(
        {.received = "controls_in",
         .rejected = "controls_rejected",
         .reason_prefix = "controls_rejected_",
         .rate = false},
        [this](const studio_CameraControl& c, const wire::SampleMeta&) { return on_control(c); });
    commands_ = &loop_.input<studio_CaptureCommand>(
        {.received = "commands_in",
         .rejected = "commands_rejected",
         .reason_prefix = "commands_rejected_",
         .rate = false},
        [this](const studio_CaptureCommand& c, const wire::SampleMeta&) { return on_command(c); });
    for (auto& setup : options_.cameras) {
      auto& w = *workers_.emplace_back(std::make_unique<CameraWorker>(std::move(setup), io_));
      loop_.thread(
          w.id(), [&w] { w.run(); }, [&w] { w.interrupt(); });
    }
    std::vector<ImageRequests::Camera> rings;
    for (auto& w : workers_) rings.push_back({w->id(), &w->ring()});
    image_requests_ = std::make_unique<ImageRequests>(loop_, std::move(rings));
    loop_.at_stop([this] {
      for (auto& w : workers_) w->finish();
    });
  }
  ~CaptureNode() override { stop(); }

  Expected<void> start() override {
    if (auto r = kept_plates_.prepare(); !r) return r;
    for (auto& w : workers_)
      if (auto r = w->start(); !r) return r;
    if (auto r = loop_.start(); !r) return r;
    for (auto& w : workers_) {
      if (auto r = w->publish_fixed_calibration(); !r) return r;
      w->publish_state();
    }
    check_disk_rate();
    return {};
  }
  void stop() override { loop_.stop(); }

  runtime::NodeHealth health() override {
    runtime::NodeHealth h = loop_.health();
    h.frame = 0;
    h.capture_ns = 0;
    for (auto& w : workers_) {
      const CameraWorker::Health c = w->health();
      h.degraded |= c.error;
      if (c.frame >= h.frame) {
        h.frame = c.frame;
        h.capture_ns = c.capture_ns;
      }
    }
    return h;
  }

 private:
  CameraWorker* worker(const std::string& id) {
    for (auto& w : workers_)
      if (w->id() == id) return w.get();
    return nullptr;
  }

  // Warns when recording every camera at the studio rate would need more than the takes disk
  // sustains (recorder: disk_mb_s, else measured now).
  void check_disk_rate() {
    const double fps = 1e9 / double(options_.clock.period_ns);
    double need = 0;
    std::string unknown;
    for (auto& w : workers_) {
      if (const auto size = w->image_size(); size.first > 0)
        need += take_bytes_per_second(size.first, size.second, fps) / 1e6;
      else
        unknown += " " + w->id();
    }
    double have = options_.disk_mb_s;
    if (have <= 0) {
      auto measured = measure_write_rate(options_.takes_dir);
      if (!measured) {
        STUDIO_LOG(warn, kLog) << measured.error().message;
        return;
      }
      have = *measured;
    }
    STUDIO_LOG(info, kLog) << "takes need " << need << " MB/s" << (unknown.empty() ? "" : " (not counted:" + unknown + ")")
                           << ", the disk sustains " << have << " MB/s";
    if (need > have)
      STUDIO_LOG(warn, kLog) << "the cameras need " << need << " MB/s to record, more than the "
                             << have << " MB/s the takes disk sustains: takes will drop frames";
  }

  runtime::Outcome on_control(const studio_CameraControl& sample) {
    const CameraControlCore c = to_core(sample);
    CameraWorker* w = worker(c.camera_id);
    if (!w) return {};  // another node's camera
    if (std::string problem = w->control(c); !problem.empty())
      return runtime::reject(c.feature == keyer::kPlateControl ? "value" : "feature", problem);
    return {};
  }

  runtime::Outcome on_command(const studio_CaptureCommand& sample) {
    const CaptureCommandCore c = to_core(sample);
    if (!valid_take_name(c.take))
      return runtime::reject("take_name", "capture command: bad take name '" + c.take +
                                              "' (letters, digits, _ - . only)");
    // A command one camera refuses (the others may take it) is one rejection per camera.
    for (auto& w : workers_)
      if (std::string problem = w->command(c); !problem.empty())
        commands_->reject({"camera", w->id() + ": " + problem});
    return {};
  }

  CaptureNodeOptions options_;
  const keyer::KeptPlates kept_plates_;
  std::vector<std::unique_ptr<CameraWorker>> workers_;
  runtime::Input<studio_CaptureCommand>* commands_ = nullptr;
  std::unique_ptr<ImageRequests> image_requests_;
  runtime::ServiceLoop loop_;  // stopped (destroyed) before the workers: declared after them
  CaptureStages stages_;
  CaptureIo io_;
};

}  // namespace

Expected<std::unique_ptr<runtime::Node>> make_capture_node(CaptureNodeOptions options,
                                                           runtime::NodeContext& context) {
  return std::make_unique<CaptureNode>(std::move(options), context);
}

}  // namespace studio::capture::node

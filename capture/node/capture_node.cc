#include "core/clock.h"
#include "capture_node.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/log.h"
#include "keyer/keyer.h"
#include "wire/capture_convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "yaml_io/rig_yaml.h"

namespace studio::capture::node {
using wire::CameraControlCore;
using wire::CameraStateCore;
using wire::CaptureCommandCore;
using wire::from_core;
using wire::to_core;

namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kLog = "capture";
constexpr std::string_view kCameraFeatures[] = {"Gain", "ExposureTime", "Focus", "Zoom", "Iris"};


bool valid_take_name(const std::string& s) {
  if (s.empty() || s == "." || s == ".." || s.size() > 63) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

}  // namespace

struct CaptureNode::Wire {
  wire::Publication<studio_AlphaMask> masks;
  wire::Publication<studio_CameraImage> images;
  wire::Publication<studio_CameraState> states;
  wire::Publication<studio_CameraCalibration> calibrations;
  wire::Subscription<studio_CameraControl> controls;
  wire::Subscription<studio_CaptureCommand> commands;
  wire::GuardCondition wake;
  wire::WaitSet waitset;
};

struct CaptureNode::Camera {
  std::string id;
  std::unique_ptr<FrameSource> source;
  std::optional<studio::Camera> calibration;
  std::optional<keyer::Keyer> keyer;
  std::thread thread;
  int plate_remaining = 0;       // frame thread only: frames still to average into the plate
  bool warned_no_plate = false;  // frame thread only

  std::mutex mutex;  // everything below
  TakeSchedule schedule;
  std::unique_ptr<Recorder> recorder;
  std::vector<std::unique_ptr<Recorder>> finishing;
  uint64_t take_frames_seen = 0;  // frames of the recording take the source delivered (+ missed)
  uint64_t recorder_drops = 0;  // queue drops of finished takes
  int plate_request = -1;       // KeyerPlate: -1 none, 0 clear, N: the next N frames
  bool error_state = false;     // a take failed (disk full, ...): stays until restart
  bool source_error = false;    // the source fails now
  std::string error;
  uint64_t last_frame = 0;
  int64_t last_capture_ns = 0;
  double image_rate = 0;
  bool image_raw = false;
  double fps = 0;
  uint64_t frames_in_window = 0;
  Clock::time_point window_start = Clock::now();
  Clock::time_point last_state = Clock::time_point::min();
  Clock::time_point last_image = Clock::time_point::min();
  bool dirty = true;
};

CaptureNode::CaptureNode(CaptureNodeOptions options, runtime::NodeContext& context)
    : options_(std::move(options)),
      kept_plates_(options_.plate_dir),
      context_(context),
      masks_published_(context.metrics.counter("masks_published")),
      images_published_(context.metrics.counter("images_published")),
      frames_recorded_(context.metrics.counter("frames_recorded")),
      frames_dropped_(context.metrics.counter("frames_dropped")),
      frames_unkeyed_(context.metrics.counter("frames_unkeyed")),
      plates_captured_(context.metrics.counter("plates_captured")),
      plate_saves_failed_(context.metrics.counter("plate_saves_failed")),
      controls_rejected_(context.metrics.counter("controls_rejected")),
      commands_rejected_(context.metrics.counter("commands_rejected")) {
  for (auto& setup : options_.cameras) {
    auto cam = std::make_unique<Camera>();
    cam->id = setup.id;
    cam->source = std::move(setup.source);
    cam->calibration = setup.calibration;
    cam->image_rate = options_.image_rate;
    cam->image_raw = options_.image_raw;
    cameras_.push_back(std::move(cam));
  }
}

CaptureNode::~CaptureNode() { stop(); }

Expected<void> CaptureNode::start() {
  const auto& p = context_.participant;
  auto fail_with = [](const Error& e) { return std::unexpected(e); };
  auto w = wire::gather([](auto&&... e) { return std::unique_ptr<Wire>(new Wire{std::move(e)...}); },
                        wire::Publication<studio_AlphaMask>::create(p),
                        wire::Publication<studio_CameraImage>::create(p),
                        wire::Publication<studio_CameraState>::create(p),
                        wire::Publication<studio_CameraCalibration>::create(p),
                        wire::Subscription<studio_CameraControl>::create(p),
                        wire::Subscription<studio_CaptureCommand>::create(p),
                        wire::GuardCondition::create(p), wire::WaitSet::create(p));
  if (!w) return fail_with(w.error());
  wire_ = std::move(*w);
  if (auto a = wire_->waitset.attach(*wire_->controls, 1); !a) return fail_with(a.error());
  if (auto a = wire_->waitset.attach(*wire_->commands, 2); !a) return fail_with(a.error());
  if (auto a = wire_->waitset.attach(wire_->wake, 3); !a) return fail_with(a.error());

  if (auto r = kept_plates_.prepare(); !r) return r;
  for (auto& cam : cameras_) {
    auto k = keyer::Keyer::create(options_.keyer);
    if (!k) return fail("camera " + cam->id + ": keyer: " + k.error().message);
    cam->keyer.emplace(std::move(*k));
    // A plate captured on command before a restart. Unreadable: the camera waits for a new one.
    if (auto loaded = kept_plates_.load(cam->id, *cam->keyer); !loaded) {
      STUDIO_LOG(warn, kLog) << cam->id << ": kept plate not used: " << loaded.error().message;
    } else if (*loaded) {
      STUDIO_LOG(info, kLog) << cam->id << ": clean plate from " << kept_plates_.path(cam->id);
    }
    if (cam->calibration) {
      wire::Owned<studio_CameraCalibration> c;
      auto fit = from_core(*cam->calibration, 0, realtime_ns(), false, c);  // the paper's model
      if (!fit) return fail(fit.error().message);
      if (fit->fitted)
        STUDIO_LOG(info, kLog) << cam->id << ": OpenCV distortion fitted to the paper's model, residual max "
                               << fit->max_residual_px << " px, RMS " << fit->rms_residual_px << " px";
      if (auto w = wire_->calibrations->write(*c); !w) return fail_with(w.error());
    }
    if (auto s = cam->source->start(); !s)
      return fail("camera " + cam->id + ": " + s.error().message);
  }
  running_ = true;
  for (auto& cam : cameras_) {
    publish_state(*cam);
    cam->thread = std::thread([this, c = cam.get()] { capture_loop(*c); });
  }
  control_thread_ = std::thread([this] { control_loop(); });
  return {};
}

void CaptureNode::stop() {
  if (!running_.exchange(false)) return;
  if (wire_) wire_->wake.trigger();
  for (auto& cam : cameras_) cam->source->stop();
  for (auto& cam : cameras_)
    if (cam->thread.joinable()) cam->thread.join();
  if (control_thread_.joinable()) control_thread_.join();
  // End takes still recording: their frames up to now are kept and take.yaml completed.
  for (auto& cam : cameras_) {
    std::lock_guard lock(cam->mutex);
    if (cam->recorder) {
      cam->recorder->stop();
      cam->finishing.push_back(std::move(cam->recorder));
    }
    for (auto& r : cam->finishing) {
      auto result = r->wait();
      if (!result) {
        STUDIO_LOG(error, kLog) << cam->id << ": " << result.error().message;
      }
    }
    cam->finishing.clear();
    cam->source->stop();
  }
  for (auto& cam : cameras_) publish_state(*cam);
}

runtime::NodeHealth CaptureNode::health() {
  runtime::NodeHealth h;
  for (auto& cam : cameras_) {
    std::lock_guard lock(cam->mutex);
    h.degraded |= cam->error_state || cam->source_error;
    if (cam->last_frame >= h.frame) {
      h.frame = cam->last_frame;
      h.capture_ns = cam->last_capture_ns;
    }
    h.input_hz += cam->fps;
    h.output_hz += cam->fps;
  }
  return h;
}

void CaptureNode::publish_state(Camera& cam) {
  CameraStateCore s;
  s.camera_id = cam.id;
  s.features = cam.source->features();
  const auto source_stats = cam.source->stats();
  {
    std::lock_guard lock(cam.mutex);
    s.features.push_back(
        {"ImageRate", cam.image_rate, 0, 1e9 / double(options_.clock.period_ns), true});
    s.features.push_back({"ImageRaw", cam.image_raw ? 1.0 : 0.0, 0, 1, true});
    s.frame = cam.last_frame;
    s.capture_ns = cam.last_capture_ns;
    s.fps = cam.fps;
    s.drops = source_stats.drops + cam.recorder_drops +
              (cam.recorder ? cam.recorder->stats().queue_drops : 0);
    s.recording = cam.recorder != nullptr;
    if (cam.schedule.recording())
      s.take = cam.schedule.recording()->name;
    else if (cam.schedule.pending())
      s.take = cam.schedule.pending()->name;
    s.state = cam.error_state || cam.source_error ? CameraStateCore::Run::kError
              : !running_                         ? CameraStateCore::Run::kStopped
              : s.recording                       ? CameraStateCore::Run::kRecording
                                                  : CameraStateCore::Run::kStreaming;
    s.error = cam.error;
    cam.dirty = false;
    cam.last_state = Clock::now();
  }
  wire::Owned<studio_CameraState> sample;
  from_core(s, sample);
  if (wire_) {
    if (auto w = wire_->states->write(*sample); !w) {
      STUDIO_LOG(warn, kLog) << cam.id << ": state: " << w.error().message;
    }
  }
}

void CaptureNode::capture_loop(Camera& cam) {
  RunMask mask;
  std::vector<uint8_t> bytes, image_bytes;
  wire::Owned<studio_AlphaMask> mask_sample;
  wire::Owned<studio_CameraImage> image_sample;
  const auto state_period = std::chrono::duration<double>(options_.state_period);
  bool source_failed = false;
  while (running_) {
    auto next = cam.source->next(std::chrono::milliseconds(200));
    if (!next) {
      if (!source_failed) {
        STUDIO_LOG(error, kLog) << cam.id << ": " << next.error().message;
      }
      source_failed = true;
      {
        std::lock_guard lock(cam.mutex);
        cam.source_error = true;
        cam.error = next.error().message;
      }
      publish_state(cam);
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      continue;
    }
    const auto now = Clock::now();
    if (*next) {
      Frame& frame = **next;
      source_failed = false;
      bool send_image = false, raw = false;
      int plate_request = -1;
      {
        std::lock_guard lock(cam.mutex);
        plate_request = std::exchange(cam.plate_request, -1);
        if (cam.source_error) {  // the source recovered
          cam.source_error = false;
          cam.error.clear();
        }
        cam.last_frame = frame.frame;
        cam.last_capture_ns = frame.capture_ns;
        ++cam.frames_in_window;
        // Recording (frame-accurate: TakeSchedule decides per studio frame number).
        auto d = cam.schedule.on_frame(frame.frame);
        if (d.ended && cam.recorder) {
          // The take's frames the source never delivered. (The source's own drop counter would
          // also count frames skipped after stop_frame, before this frame.)
          const uint64_t expected = d.ended->stop_frame.value_or(frame.frame) - d.ended->start_frame;
          cam.recorder->add_drops(expected > cam.take_frames_seen ? expected - cam.take_frames_seen
                                                                  : 0);
          cam.recorder->stop(d.ended->stop_frame);
          cam.finishing.push_back(std::move(cam.recorder));
          cam.dirty = true;
        }
        if (d.begin) {
          TakeInfo info;
          info.take = d.take.name;
          info.camera_id = cam.id;
          info.width = uint32_t(frame.image.width());
          info.height = uint32_t(frame.image.height());
          info.period_ns = options_.clock.period_ns;
          info.start_frame = d.take.start_frame;
          info.stop_frame = d.take.stop_frame;
          const auto& calib = frame.calibration ? frame.calibration : cam.calibration;
          if (calib) info.calibration_yaml = yaml::format_camera(*calib, 2);
          const std::string dir = options_.takes_dir + "/" + d.take.name + "/" + cam.id;
          auto r = Recorder::start({.dir = dir, .queue_frames = options_.queue_frames}, info);
          if (r) {
            cam.recorder = std::move(*r);
            cam.recorder->add_drops(d.missed);
            cam.take_frames_seen = d.missed;  // counted as drops already
            STUDIO_LOG(info, kLog) << cam.id << ": take " << d.take.name << " recording from frame "
                                   << frame.frame << " into " << dir;
          } else {
            STUDIO_LOG(error, kLog) << cam.id << ": " << r.error().message;
            cam.error_state = true;
            cam.error = r.error().message;
            cam.schedule.cancel();
          }
          cam.dirty = true;
        }
        if (d.record && cam.recorder) {
          ++cam.take_frames_seen;  // a refused push is a queue drop, counted by the recorder
          if (cam.recorder->push(frame))
            frames_recorded_.add();
          else
            frames_dropped_.add();
        }
        if (cam.recorder && cam.recorder->state() == RecorderState::kError) {
          cam.error_state = true;
          cam.error = cam.recorder->error();
          STUDIO_LOG(error, kLog) << cam.id << ": take " << cam.recorder->info().take
                                  << " stopped: " << cam.error;
          cam.schedule.cancel();
          cam.finishing.push_back(std::move(cam.recorder));
          cam.dirty = true;
        }
        for (auto it = cam.finishing.begin(); it != cam.finishing.end();) {
          const auto st = (*it)->state();
          if (st == RecorderState::kFinished || st == RecorderState::kError) {
            auto result = (*it)->wait();
            cam.recorder_drops += (*it)->stats().queue_drops;
            if (result) {
              STUDIO_LOG(info, kLog)
                  << cam.id << ": take " << result->take << " complete: " << result->frames
                  << " frames, " << result->drops << " drops";
            } else if (!cam.error_state) {
              cam.error_state = true;
              cam.error = result.error().message;
            }
            it = cam.finishing.erase(it);
            cam.dirty = true;
          } else {
            ++it;
          }
        }
        const double rate = cam.image_raw && cam.image_rate <= 0 ? 1.0 : cam.image_rate;
        if (rate > 0 && (cam.last_image == Clock::time_point::min() ||
                         now - cam.last_image >= std::chrono::duration<double>(1.0 / rate))) {
          send_image = true;
          raw = cam.image_raw;
          cam.last_image = now;
        }
      }

      // Key → mask codec → AlphaMask (unless keying runs elsewhere: masks: false).
      if (options_.publish_masks && plate_request >= 0) {
        cam.keyer->clear_plate();
        cam.plate_remaining = plate_request;
        cam.warned_no_plate = false;
        if (plate_request == 0) kept_plates_.remove(cam.id);
      }
      if (!options_.publish_masks) {
        // studio-keyer --config keys the raw images on another machine.
      } else if (cam.plate_remaining > 0) {  // clean plate on command: no mask meanwhile
        if (auto r = cam.keyer->capture_plate(frame.image.view()); !r) {
          STUDIO_LOG(warn, kLog) << cam.id << ": clean plate: " << r.error().message;
          cam.plate_remaining = 0;
        } else if (--cam.plate_remaining == 0) {
          plates_captured_.add();
          STUDIO_LOG(info, kLog) << cam.id << ": clean plate captured ("
                                 << cam.keyer->plate_frames() << " frames)";
          if (auto r = kept_plates_.save(cam.id, *cam.keyer); !r) {
            plate_saves_failed_.add();
            STUDIO_LOG(warn, kLog) << cam.id << ": clean plate not kept: " << r.error().message;
          }
        }
      } else if (options_.keyer.mode == keyer::KeyMode::kDifference && !cam.keyer->has_plate()) {
        frames_unkeyed_.add();
        if (!cam.warned_no_plate) {
          STUDIO_LOG(warn, kLog) << cam.id << ": no clean plate yet (send CameraControl "
                                 << keyer::kPlateControl << " N); frames are not keyed";
          cam.warned_no_plate = true;
        }
      } else if (auto k = cam.keyer->key(frame.image.view(), mask); k) {
        encode_mask(mask, options_.coding, bytes);
        from_core(cam.id, frame.frame, frame.capture_ns, bytes, mask.width(), mask.height(),
                  mask_sample);
        if (wire_->masks->write(*mask_sample)) {
          masks_published_.add();
          context_.metrics.latency().record(realtime_ns() - frame.capture_ns);
        }
      } else {
        STUDIO_LOG(warn, kLog) << cam.id << ": keyer: " << k.error().message;
      }

      if (send_image) {
        const int w = frame.image.width(), h = frame.image.height();
        if (raw) {
          const auto* p = reinterpret_cast<const uint8_t*>(frame.image.data());
          image_bytes.assign(p, p + std::size_t(w) * h * 3);
        } else {
          cv::Mat rgb(h, w, CV_8UC3, frame.image.data());
          cv::Mat bgr;
          cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
          cv::imencode(".jpg", bgr, image_bytes, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
        }
        from_core(cam.id, frame.frame, frame.capture_ns, w, h, !raw, image_bytes, image_sample);
        if (wire_->images->write(*image_sample)) images_published_.add();
      }
    }
    bool publish = false;
    {
      std::lock_guard lock(cam.mutex);
      const auto elapsed = std::chrono::duration<double>(now - cam.window_start);
      if (elapsed >= state_period) {
        cam.fps = double(cam.frames_in_window) / elapsed.count();
        cam.frames_in_window = 0;
        cam.window_start = now;
        publish = true;
      }
      publish |= cam.dirty;
    }
    if (publish) publish_state(cam);
  }
}

void CaptureNode::control_loop() {
  while (running_) {
    wire_->waitset.wait(std::chrono::milliseconds(200));
    wire_->wake.take();
    for (auto& s : wire_->controls->take()) {
      if (!s.meta.valid_data) continue;
      handle_control(to_core(*s.data));
    }
    for (auto& s : wire_->commands->take()) {
      if (!s.meta.valid_data) continue;
      handle_command(to_core(*s.data));
    }
  }
}

void CaptureNode::handle_control(const CameraControlCore& c) {
  Camera* cam = nullptr;
  for (auto& x : cameras_)
    if (x->id == c.camera_id) cam = x.get();
  if (!cam) return;  // another node's camera
  std::string problem;
  if (c.feature == keyer::kPlateControl) {
    // For whichever process keys this camera: here only when it keys in-process.
    if (!options_.publish_masks) return;
    if (!keyer::valid_plate_request(c.value)) {
      problem = "camera " + cam->id + ": " + std::string(keyer::kPlateControl) + " " +
                std::to_string(c.value) + ": expected 0 (clear) or a frame count 1.." +
                std::to_string(keyer::kMaxPlateFrames);
    } else {
      std::lock_guard lock(cam->mutex);
      cam->plate_request = int(c.value);
      STUDIO_LOG(info, kLog) << cam->id << ": "
                             << (c.value == 0 ? std::string("clean plate cleared")
                                              : "capturing a clean plate from the next " +
                                                    std::to_string(int(c.value)) + " frame(s)");
    }
  } else if (c.feature == "ImageRate") {
    std::lock_guard lock(cam->mutex);
    cam->image_rate = std::clamp(c.value, 0.0, 1e9 / double(options_.clock.period_ns));
  } else if (c.feature == "ImageRaw") {
    std::lock_guard lock(cam->mutex);
    cam->image_raw = c.value != 0;
  } else if (std::find(std::begin(kCameraFeatures), std::end(kCameraFeatures), c.feature) ==
             std::end(kCameraFeatures)) {
    problem = "camera " + cam->id + ": feature '" + c.feature +
              "' is not allowed (allowed: Gain, "
              "ExposureTime, Focus, Zoom, Iris, ImageRate, ImageRaw)";
  } else if (auto v = cam->source->set_feature(c.feature, c.value); !v) {
    problem = v.error().message;
  } else {
    STUDIO_LOG(info, kLog) << cam->id << ": " << c.feature << " = " << *v << " (asked " << c.value
                           << ")";
  }
  {
    std::lock_guard lock(cam->mutex);
    if (!problem.empty()) {
      controls_rejected_.add();
      STUDIO_LOG(warn, kLog) << problem;
      cam->error = problem;
    } else if (!cam->error_state) {
      cam->error.clear();
    }
  }
  publish_state(*cam);
}

void CaptureNode::handle_command(const CaptureCommandCore& c) {
  if (!valid_take_name(c.take)) {
    commands_rejected_.add();
    STUDIO_LOG(warn, kLog) << "capture command: bad take name '" << c.take
                           << "' (letters, digits, _ - . only)";
    return;
  }
  for (auto& cam : cameras_) {
    std::string problem;
    {
      std::lock_guard lock(cam->mutex);
      if (c.start) {
        if (auto r = cam->schedule.start(c.take, c.at_frame); !r) problem = r.error().message;
      } else if (auto r = cam->schedule.stop(c.take, c.at_frame); !r) {
        problem = r.error().message;
      } else if (*r != c.at_frame) {
        problem = "take " + c.take + ": stop frame " + std::to_string(c.at_frame) +
                  " had passed; stopping at " + std::to_string(*r);
      }
      if (!problem.empty())
        cam->error = problem;
      else if (!cam->error_state)
        cam->error.clear();
    }
    if (!problem.empty()) {
      commands_rejected_.add();
      STUDIO_LOG(warn, kLog) << cam->id << ": " << problem;
    } else {
      STUDIO_LOG(info, kLog) << cam->id << ": take " << c.take << (c.start ? " starts" : " stops")
                             << " at frame " << c.at_frame;
    }
    publish_state(*cam);
  }
}

}  // namespace studio::capture::node

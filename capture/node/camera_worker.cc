#include "camera_worker.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "core/clock.h"
#include "core/log.h"

namespace studio::capture::node {
namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kLog = "capture";
constexpr std::string_view kCameraFeatures[] = {
    "Gain", "ExposureTime", "Focus", "Zoom", "Iris", "BalanceRatioRed", "BalanceRatioBlue"};

}  // namespace

CameraWorker::CameraWorker(CameraSetup setup, const CaptureIo& io)
    : io_(io),
      id_(std::move(setup.id)),
      source_(std::move(setup.source)),
      calibration_(std::move(setup.calibration)),
      tracked_(setup.tracked),
      report_tracker_(setup.report_tracker),
      lens_table_(std::move(setup.lens_table)),
      modelled_readout_ns_(setup.modelled_readout_ns),
      image_rate_(io.options.image_rate),
      image_raw_(io.options.image_raw) {
  if (report_tracker_) {
    freed_counters_.push_back(&io_.loop.counter("freed_accepted"));
    for (std::size_t r = 0; r < kFreeDRejectCount; ++r)
      freed_counters_.push_back(
          &io_.loop.counter(std::string("freed_rejected_") + to_string(FreeDReject(r))));
  }
}

Expected<void> CameraWorker::start() {
  auto k = keyer::Keyer::create(io_.options.keyer);
  if (!k) return fail("camera " + id_ + ": keyer: " + k.error().message);
  keyer_.emplace(std::move(*k));
  // A plate captured on command before a restart. Unreadable: the camera waits for a new one.
  io_.kept_plates.restore(id_, keyer_->keyer(), kLog);
  if (auto s = source_->start(); !s) return fail("camera " + id_ + ": " + s.error().message);
  if (!tracked_) {  // the lens as calibrated: the Zoom/Focus values now
    double zoom = NAN, focus = NAN;
    for (const Feature& f : source_->features()) {
      if (f.name == "Zoom") zoom = f.value;
      if (f.name == "Focus") focus = f.value;
    }
    std::lock_guard lock(mutex_);
    lens_.emplace(calibration_, lens_table_, zoom, focus);
  }
  return {};
}

void CameraWorker::run() {
  while (io_.loop.running()) {
    auto next = source_->next(std::chrono::milliseconds(200));
    if (!next) {
      on_source_error(next.error());
      continue;
    }
    const auto now = Clock::now();
    if (*next) on_frame(**next, now);
    if (tracked_) check_tracking();
    if (state_due(now)) publish_state();
  }
}

void CameraWorker::on_source_error(const Error& error) {
  if (!source_failed_) STUDIO_LOG(error, kLog) << id_ << ": " << error.message;
  source_failed_ = true;
  {
    std::lock_guard lock(mutex_);
    source_error_ = true;
    error_ = error.message;
  }
  publish_state();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
}

void CameraWorker::on_frame(Frame& frame, Clock::time_point now) {
  // capture_ns -> here: the modelled read-out, then whatever came on top (capture_stages.h).
  const int64_t grabbed_ns = realtime_ns();
  io_.stages.add(CaptureStages::readout_model, double(modelled_readout_ns_) * 1e-6);
  io_.stages.add(CaptureStages::grab_late,
                 double(grabbed_ns - frame.capture_ns - modelled_readout_ns_) * 1e-6);
  source_failed_ = false;
  io_.frames_captured.add();
  bool send = false, raw = false;
  {
    std::lock_guard lock(mutex_);
    if (source_error_) {  // the source recovered
      source_error_ = false;
      error_.clear();
    }
    last_frame_ = frame.frame;
    last_capture_ns_ = frame.capture_ns;
    ++frames_in_window_;
    record(frame);
    send = image_due(now, raw);
  }
  if (frame.calibration) publish_tracked_calibration(frame);
  // Key (unless keying runs elsewhere: masks: false) → the image into the ring, before its mask
  // goes out (moved, not copied, unless this frame's image is also published) → mask codec →
  // AlphaMask.
  const auto key_start = Clock::now();
  const bool keyed = io_.options.publish_masks && key(frame);
  if (keyed) io_.stages.add(CaptureStages::key, Clock::now() - key_start);
  if (send) {
    ring_.push(frame.frame, frame.capture_ns, frame.image);
  } else {
    ring_.push(frame.frame, frame.capture_ns, std::move(frame.image));
  }
  if (keyed) publish_mask(frame);
  if (send) send_image(frame, raw);
}

bool CameraWorker::image_due(Clock::time_point now, bool& raw) {
  const double rate = image_raw_ && image_rate_ <= 0 ? 1.0 : image_rate_;
  if (rate <= 0 || (last_image_ != Clock::time_point::min() &&
                    now - last_image_ < std::chrono::duration<double>(1.0 / rate)))
    return false;
  raw = image_raw_;
  last_image_ = now;
  return true;
}

bool CameraWorker::key(const Frame& frame) {
  const keyer::PlateKeyer::Result r = keyer_->frame(frame.image.view(), mask_);
  if (r.cleared) io_.kept_plates.remove(id_);
  using Step = keyer::PlateKeyer::Step;
  switch (r.step) {
    case Step::kPlateFrame:  // clean plate on command: no mask meanwhile
      return false;
    case Step::kPlateCaptured:
      io_.plates_captured.add();
      STUDIO_LOG(info, kLog) << id_ << ": clean plate captured (" << keyer_->keyer().plate_frames()
                             << " frames)";
      if (!io_.kept_plates.keep(id_, keyer_->keyer(), kLog)) io_.plate_saves_failed.add();
      return false;
    case Step::kNoPlate:
      io_.frames_unkeyed.add();
      if (r.first)
        STUDIO_LOG(warn, kLog) << id_ << ": no clean plate yet (send CameraControl "
                               << keyer::kPlateControl << " N); frames are not keyed";
      return false;
    case Step::kRefused:
      STUDIO_LOG(warn, kLog) << id_ << ": keyer: " << r.error.message;
      return false;
    case Step::kKeyed:
      break;
  }
  return true;
}

void CameraWorker::publish_mask(const Frame& frame) {
  const auto t0 = Clock::now();
  encode_mask(mask_, io_.options.coding, mask_bytes_);
  from_core(id_, frame.frame, frame.capture_ns, mask_bytes_, mask_.width(), mask_.height(),
            mask_sample_);
  const auto t1 = Clock::now();
  const bool written = bool(io_.masks.write(*mask_sample_));
  const int64_t written_ns = realtime_ns();
  io_.stages.add(CaptureStages::code, t1 - t0);
  io_.stages.add(CaptureStages::write, Clock::now() - t1);
  if (!written) return;
  io_.stages.add(CaptureStages::capture_to_mask, double(written_ns - frame.capture_ns) * 1e-6);
  io_.loop.completed(frame.frame, frame.capture_ns);
}

void CameraWorker::send_image(const Frame& frame, bool raw) {
  const int w = frame.image.width(), h = frame.image.height();
  if (raw) {
    const auto* p = reinterpret_cast<const uint8_t*>(frame.image.data());
    image_bytes_.assign(p, p + std::size_t(w) * h * 3);
  } else {
    cv::Mat rgb(h, w, CV_8UC3, const_cast<Rgb8*>(frame.image.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    cv::imencode(".jpg", bgr, image_bytes_, {cv::IMWRITE_JPEG_QUALITY, io_.options.jpeg_quality});
  }
  from_core(id_, frame.frame, frame.capture_ns, w, h, !raw, image_bytes_, image_sample_);
  (void)io_.images.write(*image_sample_);
}

bool CameraWorker::state_due(Clock::time_point now) {
  std::lock_guard lock(mutex_);
  const auto elapsed = std::chrono::duration<double>(now - window_start_);
  bool due = dirty_;
  if (elapsed.count() >= io_.options.state_period) {
    fps_ = double(frames_in_window_) / elapsed.count();
    frames_in_window_ = 0;
    window_start_ = now;
    due = true;
  }
  return due;
}

std::string CameraWorker::control(const CameraControlCore& c) {
  std::string problem;
  if (c.feature == keyer::kPlateControl) {
    // For whichever process keys this camera: here only when it keys in-process.
    if (!io_.options.publish_masks) return {};
    if (const auto frames = keyer::plate_request(c.value); !frames) {
      problem = "camera " + id_ + ": " + frames.error().message;
    } else {
      keyer_->request(*frames);
      STUDIO_LOG(info, kLog) << id_ << ": " << keyer::plate_request_text(*frames);
    }
  } else if (c.feature == "ImageRate") {
    std::lock_guard lock(mutex_);
    image_rate_ = std::clamp(c.value, 0.0, 1e9 / double(io_.options.clock.period_ns));
  } else if (c.feature == "ImageRaw") {
    std::lock_guard lock(mutex_);
    image_raw_ = c.value != 0;
  } else if (std::find(std::begin(kCameraFeatures), std::end(kCameraFeatures), c.feature) ==
             std::end(kCameraFeatures)) {
    problem = "camera " + id_ + ": feature '" + c.feature +
              "' is not allowed (allowed: Gain, ExposureTime, Focus, Zoom, Iris, "
              "BalanceRatioRed, BalanceRatioBlue, ImageRate, ImageRaw)";
  } else if (auto v = source_->set_feature(c.feature, c.value); !v) {
    problem = v.error().message;
  } else {
    STUDIO_LOG(info, kLog) << id_ << ": " << c.feature << " = " << *v << " (asked " << c.value
                           << ")";
    if (c.feature == "Zoom" || c.feature == "Focus") lens_moved(c.feature, *v);
  }
  {
    std::lock_guard lock(mutex_);
    if (!problem.empty())
      error_ = problem;
    else if (!error_state_)
      error_.clear();
  }
  publish_state();
  return problem;
}

std::string CameraWorker::command(const CaptureCommandCore& c) {
  std::string problem;
  {
    std::lock_guard lock(mutex_);
    if (c.start) {
      if (auto r = schedule_.start(c.take, c.at_frame); !r) problem = r.error().message;
    } else if (auto r = schedule_.stop(c.take, c.at_frame); !r) {
      problem = r.error().message;
    } else if (*r != c.at_frame) {
      problem = "take " + c.take + ": stop frame " + std::to_string(c.at_frame) +
                " had passed; stopping at " + std::to_string(*r);
    }
    if (!problem.empty())
      error_ = problem;
    else if (!error_state_)
      error_.clear();
  }
  if (problem.empty())
    STUDIO_LOG(info, kLog) << id_ << ": take " << c.take << (c.start ? " starts" : " stops")
                           << " at frame " << c.at_frame;
  publish_state();
  return problem;
}

void CameraWorker::publish_state() {
  CameraStateCore s;
  s.camera_id = id_;
  s.features = source_->features();
  const auto source_stats = source_->stats();
  {
    std::lock_guard lock(mutex_);
    const double max_rate = 1e9 / double(io_.options.clock.period_ns);
    s.features.push_back({"ImageRate", image_rate_, 0, max_rate, true});
    s.features.push_back({"ImageRaw", image_raw_ ? 1.0 : 0.0, 0, 1, true});
    s.frame = last_frame_;
    s.capture_ns = last_capture_ns_;
    s.fps = fps_;
    s.drops =
        source_stats.drops + recorder_drops_ + (recorder_ ? recorder_->stats().queue_drops : 0);
    s.recording = recorder_ != nullptr;
    if (schedule_.recording())
      s.take = schedule_.recording()->name;
    else if (schedule_.pending())
      s.take = schedule_.pending()->name;
    using Run = CameraStateCore::Run;
    s.state = error_state_ || source_error_ ? Run::kError
              : !io_.loop.running()         ? Run::kStopped
              : s.recording                 ? Run::kRecording
                                            : Run::kStreaming;
    s.error = error_;
    if (const std::string p = calibration_problem(); !p.empty()) {
      s.calibration_valid = false;
      if (s.error.empty()) s.error = p;
    }
    s.time_source = source_->time_source();
    dirty_ = false;
  }
  wire::Owned<studio_CameraState> sample;
  from_core(s, sample);
  (void)io_.states.write(*sample);
}

CameraWorker::Health CameraWorker::health() {
  std::lock_guard lock(mutex_);
  return {error_state_ || source_error_, last_frame_, last_capture_ns_};
}

}  // namespace studio::capture::node

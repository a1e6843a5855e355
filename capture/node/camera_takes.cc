// The takes of one camera (camera_worker.h): recording decided per studio frame by the
// TakeSchedule, recorders started, fed, ended and reaped; the end of takes at stop.
#include "camera_worker.h"
#include "core/log.h"
#include "yaml_io/rig_yaml.h"

namespace studio::capture::node {
namespace {
constexpr const char* kLog = "capture";
}  // namespace

// Recording is frame-accurate: TakeSchedule decides per studio frame number.
void CameraWorker::record(const Frame& frame) {
  const TakeSchedule::Decision d = schedule_.on_frame(frame.frame);
  if (d.ended && recorder_) {
    // The take's frames the source never delivered. (The source's own drop counter would also
    // count frames skipped after stop_frame, before this frame.)
    const uint64_t expected = d.ended->stop_frame.value_or(frame.frame) - d.ended->start_frame;
    recorder_->add_drops(expected > take_frames_seen_ ? expected - take_frames_seen_ : 0);
    recorder_->stop(d.ended->stop_frame);
    finishing_.push_back(std::move(recorder_));
    dirty_ = true;
  }
  if (d.begin) begin_take(frame, d);
  if (d.record && recorder_) {
    ++take_frames_seen_;  // a refused push is a queue drop, counted by the recorder
    (recorder_->push(frame) ? io_.frames_recorded : io_.frames_dropped).add();
  }
  if (recorder_ && recorder_->state() == RecorderState::kError) {
    error_state_ = true;
    error_ = recorder_->error();
    STUDIO_LOG(error, kLog) << id_ << ": take " << recorder_->info().take << " stopped: " << error_;
    schedule_.cancel();
    finishing_.push_back(std::move(recorder_));
    dirty_ = true;
  }
  reap_finished_takes();
}

void CameraWorker::begin_take(const Frame& frame, const TakeSchedule::Decision& d) {
  TakeInfo info;
  info.take = d.take.name;
  info.camera_id = id_;
  info.width = uint32_t(frame.image.width());
  info.height = uint32_t(frame.image.height());
  info.period_ns = io_.options.clock.period_ns;
  info.start_frame = d.take.start_frame;
  info.stop_frame = d.take.stop_frame;
  const auto& calib = frame.calibration ? frame.calibration : calibration_;
  if (calib) info.calibration_yaml = yaml::format_camera(*calib, 2);
  const std::string dir = io_.options.takes_dir + "/" + d.take.name + "/" + id_;
  auto r = Recorder::start({.dir = dir,
                            .queue_frames = io_.options.queue_frames,
                            .sync_interval_ms = io_.options.sync_interval_ms},
                           info);
  if (r) {
    recorder_ = std::move(*r);
    recorder_->add_drops(d.missed);
    take_frames_seen_ = d.missed;  // counted as drops already
    STUDIO_LOG(info, kLog) << id_ << ": take " << d.take.name << " recording from frame "
                           << frame.frame << " into " << dir;
  } else {
    STUDIO_LOG(error, kLog) << id_ << ": " << r.error().message;
    error_state_ = true;
    error_ = r.error().message;
    schedule_.cancel();
  }
  dirty_ = true;
}

void CameraWorker::reap_finished_takes() {
  for (auto it = finishing_.begin(); it != finishing_.end();) {
    const auto st = (*it)->state();
    if (st != RecorderState::kFinished && st != RecorderState::kError) {
      ++it;
      continue;
    }
    auto result = (*it)->wait();
    recorder_drops_ += (*it)->stats().queue_drops;
    if (result) {
      STUDIO_LOG(info, kLog) << id_ << ": take " << result->take << " complete: " << result->frames
                             << " frames, " << result->drops << " drops";
    } else if (!error_state_) {
      error_state_ = true;
      error_ = result.error().message;
    }
    it = finishing_.erase(it);
    dirty_ = true;
  }
}

void CameraWorker::finish() {
  {
    std::lock_guard lock(mutex_);
    if (recorder_) {
      recorder_->stop();
      finishing_.push_back(std::move(recorder_));
    }
    for (auto& r : finishing_)
      if (auto result = r->wait(); !result)
        STUDIO_LOG(error, kLog) << id_ << ": " << result.error().message;
    finishing_.clear();
  }
  source_->stop();
  publish_state();
}

}  // namespace studio::capture::node

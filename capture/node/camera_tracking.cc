// Tracked cameras in the capture node (camera_worker.h): per-frame CameraCalibration, the
// tracker's silence in CameraState, the Free-D listener's counters.
#include "camera_worker.h"
#include "core/clock.h"
#include "core/log.h"

namespace studio::capture::node {
namespace {
constexpr const char* kLog = "capture";
}  // namespace

Expected<void> CameraWorker::publish_fixed_calibration() {
  if (!calibration_) return {};
  wire::Owned<studio_CameraCalibration> c;
  // The wire carries the paper's model: OpenCV distortion is fitted or refused here.
  auto fit = from_core(*calibration_, 0, realtime_ns(), false, c);
  if (!fit) return fail(id_ + ": " + fit.error().message);
  if (fit->fitted)
    STUDIO_LOG(info, kLog) << id_
                           << ": OpenCV distortion fitted to the paper's model, residual max "
                           << fit->max_residual_px << " px, RMS " << fit->rms_residual_px << " px";
  return io_.calibrations.write(*c);
}

void CameraWorker::publish_tracked_calibration(const Frame& frame) {
  auto r = from_core(*frame.calibration, frame.frame, frame.capture_ns, true, calibration_sample_);
  if (!r) {
    STUDIO_LOG(warn, kLog) << id_ << ": frame " << frame.frame << ": " << r.error().message;
    return;
  }
  (void)io_.calibrations.write(*calibration_sample_);
}

void CameraWorker::check_tracking() {
  const TrackingStatus t = tracked_->status(realtime_ns());
  {
    std::lock_guard lock(mutex_);
    if (t.silent != tracker_silent_) {
      dirty_ = true;
      if (t.silent)
        STUDIO_LOG(warn, kLog) << id_ << ": free-d tracker id "
                               << int(tracked_->options().camera.freed_id) << " is silent";
      else
        STUDIO_LOG(info, kLog) << id_ << ": free-d tracker back";
    }
    tracker_silent_ = t.silent;
    tracker_silent_s_ = t.since_s;
  }
  if (!report_tracker_) return;
  const FreeDListenerStats s = tracked_->listener().stats();
  freed_counters_[0]->add(s.accepted - reported_.accepted);
  for (std::size_t r = 0; r < kFreeDRejectCount; ++r)
    freed_counters_[r + 1]->add(s.rejected[r] - reported_.rejected[r]);
  reported_ = s;
}

void CameraWorker::lens_moved(const std::string& feature, double value) {
  std::optional<Camera> republish;
  uint64_t frame = 0;
  {
    std::lock_guard lock(mutex_);
    if (!lens_) return;
    const LensCalibration::Change c = lens_->on_feature(feature, value);
    if (c.validity_changed) {
      dirty_ = true;
      if (!lens_->valid()) STUDIO_LOG(warn, kLog) << id_ << ": " << lens_->problem();
    }
    if (c.republish) {
      calibration_ = lens_->camera();
      republish = calibration_;
      frame = last_frame_;
    }
  }
  if (!republish) return;
  wire::Owned<studio_CameraCalibration> s;
  if (auto r = from_core(*republish, frame, realtime_ns(), false, s); !r) {
    STUDIO_LOG(warn, kLog) << id_ << ": " << r.error().message;
    return;
  }
  STUDIO_LOG(info, kLog) << id_ << ": " << feature << " " << value << ": intrinsics fx "
                         << republish->intrinsics.fx << " from the lens table";
  (void)io_.calibrations.write(*s);
}

std::string CameraWorker::calibration_problem() const {
  if (lens_ && !lens_->valid()) return lens_->problem();
  if (tracked_ && tracker_silent_) {
    const std::string id = std::to_string(int(tracked_->options().camera.freed_id));
    if (tracker_silent_s_ < 0) return "free-d tracker id " + id + ": no packet received";
    return "free-d tracker id " + id + ": silent for " +
           std::to_string(int(tracker_silent_s_ * 10) / 10.0).substr(0, 4) + " s";
  }
  return {};
}

}  // namespace studio::capture::node

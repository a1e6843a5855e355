#pragma once
// One camera of the capture node (capture_node.h): its grab thread's work per frame — takes
// recorded on command (TakeSchedule + Recorder), the in-process key (keyer::PlateKeyer) and its
// AlphaMask, the latest-image service (CameraImage) — and its CameraState. The node's loop
// thread applies CameraControl and CaptureCommand through control() and command().
//
// Threads: run() is the camera's grab thread (a runtime::ServiceLoop thread); control(),
// command(), publish_state() and health() may be called from the loop thread meanwhile. The
// state they share is guarded by the worker's mutex; the keyer and the image buffers belong to
// the grab thread.

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "capture/recorder.h"
#include "capture/take_schedule.h"
#include "capture_node.h"
#include "capture_stages.h"
#include "image_ring.h"
#include "wire/capture_convert.h"
#include "keyer/config/kept_plates.h"
#include "keyer/plate_keyer.h"
#include "runtime/service_loop.h"

namespace studio::capture::node {

using wire::CameraControlCore;
using wire::CameraStateCore;
using wire::CaptureCommandCore;
using wire::from_core;
using wire::to_core;

// What every camera publishes through and counts into; owned by the node.
struct CaptureIo {
  const CaptureNodeOptions& options;
  const keyer::KeptPlates& kept_plates;
  runtime::ServiceLoop& loop;
  runtime::Output<studio_AlphaMask>& masks;
  runtime::Output<studio_CameraImage>& images;
  runtime::Output<studio_CameraState>& states;
  runtime::Output<studio_CameraCalibration>& calibrations;  // at start; per frame when tracked
  runtime::Counter& frames_captured;
  runtime::Counter& frames_recorded;
  runtime::Counter& frames_dropped;
  runtime::Counter& frames_unkeyed;      // difference key without a clean plate yet
  runtime::Counter& plates_captured;     // KeyerPlate requests completed
  runtime::Counter& plate_saves_failed;  // completed plates that could not be kept in plate_dir
  CaptureStages& stages;                 // where a frame's time goes (capture_stages.h)
};

class CameraWorker {
 public:
  CameraWorker(CameraSetup setup, const CaptureIo& io);

  const std::string& id() const { return id_; }
  const std::optional<studio::Camera>& calibration() const { return calibration_; }
  // The last second of frames, for frame-exact image requests (image_ring.h).
  const ImageRing& ring() const { return ring_; }
  // The camera's image size when known before the first frame (calibration, lens table); 0, 0
  // otherwise.
  std::pair<int, int> image_size() const {
    if (calibration_) return {calibration_->width, calibration_->height};
    if (tracked_) return {tracked_->options().camera.width, tracked_->options().camera.height};
    return {0, 0};
  }

  // Creates the keyer (with a plate kept from before a restart) and starts the source.
  Expected<void> start();
  // The grab thread: frames until the loop stops.
  void run();
  // Unblocks run() (the source stops delivering).
  void interrupt() { source_->stop(); }
  // After run() ended: ends a take still recording (its frames so far kept, take.yaml completed)
  // and publishes the last state.
  void finish();

  // CameraControl for this camera; the problem, or "" when applied.
  std::string control(const CameraControlCore& c);
  // CaptureCommand (take name already checked); the problem, or "" when scheduled.
  std::string command(const CaptureCommandCore& c);
  void publish_state();
  // The calibration to publish at start (fixed cameras), as a sample; false with the error.
  Expected<void> publish_fixed_calibration();

  struct Health {
    bool error = false;
    uint64_t frame = 0;
    int64_t capture_ns = 0;
  };
  Health health();

 private:
  void on_frame(Frame& frame, std::chrono::steady_clock::time_point now);
  void on_source_error(const Error& error);
  // Under mutex_: the take schedule's decision for this frame, applied.
  void record(const Frame& frame);
  void begin_take(const Frame& frame, const TakeSchedule::Decision& d);
  void reap_finished_takes();
  // Whether an image is due (mutex_ held); sets `raw`.
  bool image_due(std::chrono::steady_clock::time_point now, bool& raw);
  // Keys the frame into mask_; true when the mask should go out (publish_mask).
  bool key(const Frame& frame);
  void publish_mask(const Frame& frame);
  void send_image(const Frame& frame, bool raw);
  // Every state_period: the fps over the window; true when a state should go out.
  bool state_due(std::chrono::steady_clock::time_point now);
  // Tracked cameras (camera_tracking.cc): the frame's CameraCalibration (tracked: true); the
  // tracker's silence into the state; the listener's counters into the node's.
  void publish_tracked_calibration(const Frame& frame);
  void check_tracking();
  // After a Zoom/Focus change (control()): new intrinsics published, or the calibration marked
  // invalid.
  void lens_moved(const std::string& feature, double value);
  // Under mutex_: what the state says about the calibration ("" = valid).
  std::string calibration_problem() const;

  const CaptureIo& io_;
  std::string id_;
  std::unique_ptr<FrameSource> source_;
  std::optional<studio::Camera> calibration_;
  TrackedSource* tracked_ = nullptr;
  bool report_tracker_ = false;
  std::optional<LensTableOptions> lens_table_;
  int64_t modelled_readout_ns_ = 0;
  ImageRing ring_{25};
  // Grab thread only.
  wire::Owned<studio_CameraCalibration> calibration_sample_;
  FreeDListenerStats reported_{};
  std::vector<runtime::Counter*> freed_counters_;  // accepted, then rejected by reason
  std::optional<keyer::PlateKeyer> keyer_;
  RunMask mask_;
  std::vector<uint8_t> mask_bytes_, image_bytes_;
  wire::Owned<studio_AlphaMask> mask_sample_;
  wire::Owned<studio_CameraImage> image_sample_;
  bool source_failed_ = false;

  std::mutex mutex_;  // everything below
  TakeSchedule schedule_;
  std::unique_ptr<Recorder> recorder_;
  std::vector<std::unique_ptr<Recorder>> finishing_;
  uint64_t take_frames_seen_ = 0;  // frames of the recording take the source delivered (+ missed)
  uint64_t recorder_drops_ = 0;    // queue drops of finished takes
  bool error_state_ = false;       // a take failed (disk full, ...): stays until restart
  bool source_error_ = false;      // the source fails now
  std::string error_;
  uint64_t last_frame_ = 0;
  int64_t last_capture_ns_ = 0;
  double image_rate_ = 0;
  bool image_raw_ = false;
  double fps_ = 0;
  uint64_t frames_in_window_ = 0;
  std::chrono::steady_clock::time_point window_start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_image_ = std::chrono::steady_clock::time_point::min();
  bool dirty_ = true;
  std::optional<LensCalibration> lens_;  // fixed cameras: zoom/focus vs the calibration
  bool tracker_silent_ = false;
  double tracker_silent_s_ = -1;
};

}  // namespace studio::capture::node

#pragma once
// The capture node (issue 3 item 7): per camera, one capture thread that takes frames from the
// camera's FrameSource and
//   - keys them in-process (keyer library) and publishes AlphaMask (mask codec bytes) every frame
//     (the paper's chroma-key service);
//   - publishes CameraImage at `image_rate` Hz (JPEG; raw RGB8 while the pseudo-feature ImageRaw
//     is 1): the latest-image service;
//   - records takes on command (TakeSchedule + Recorder, frame-accurate, DESIGN §5);
//   - publishes CameraState (features read back, fps, drops, recording, take, state, error) every
//     `state_period` and whenever something changes.
// A control thread waits on studio/camera/control and studio/capture/command: CameraControl for
// an allow-listed GenICam feature (Gain, ExposureTime, Focus, Zoom, Iris) is applied through
// FrameSource::set_feature and the read-back value is published in CameraState; ImageRate and
// ImageRaw are the node's own pseudo-features; KeyerPlate (keyer/keyer.h) captures a clean plate
// for an in-process difference key (ignored with masks: false: the keyer node honours it then).
// CaptureCommand schedules start/stop per camera.
// The calibration of every camera (rig file, else the source's own) is published on
// studio/camera/calibration (transient-local) at start.

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "capture/recorder.h"
#include "capture/take_schedule.h"
#include "core/camera.h"
#include "core/mask_codec.h"
#include "keyer/keyer_options.h"
#include "kept_plates.h"
#include "runtime/service.h"

namespace studio::wire {
struct CameraControlCore;  // wire/capture_convert.h
struct CaptureCommandCore;
}  // namespace studio::wire

namespace studio::capture::node {

struct CameraSetup {
  std::string id;
  std::unique_ptr<FrameSource> source;
  std::optional<Camera> calibration;
};

struct CaptureNodeOptions {
  FrameClock clock;
  std::string takes_dir = "takes";
  std::size_t queue_frames = 50;
  keyer::KeyerOptions keyer;
  MaskCoding coding = MaskCoding::kRowDelta;
  double image_rate = 5;  // Hz, 0 = no images
  int jpeg_quality = 85;
  bool image_raw = false;
  bool publish_masks = true;  // false: no in-process keying (studio-keyer --config keys the images)
  std::string plate_dir;      // difference key: plates captured on command kept as <id>.png
  double state_period = 1.0;  // seconds
  std::vector<CameraSetup> cameras;
};

class CaptureNode : public runtime::Node {
 public:
  CaptureNode(CaptureNodeOptions options, runtime::NodeContext& context);
  ~CaptureNode() override;
  Expected<void> start() override;
  void stop() override;
  runtime::NodeHealth health() override;

  struct Camera;  // per-camera state (capture_node.cc)
  struct Wire;

 private:
  void capture_loop(Camera& cam);
  void control_loop();
  void handle_control(const wire::CameraControlCore& c);
  void handle_command(const wire::CaptureCommandCore& c);
  void publish_state(Camera& cam);

  CaptureNodeOptions options_;
  const keyer::KeptPlates kept_plates_;  // options_.plate_dir
  runtime::NodeContext& context_;
  std::unique_ptr<Wire> wire_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::atomic<bool> running_{false};
  std::thread control_thread_;
  runtime::Counter& masks_published_;
  runtime::Counter& images_published_;
  runtime::Counter& frames_recorded_;
  runtime::Counter& frames_dropped_;
  runtime::Counter& frames_unkeyed_;   // difference key without a clean plate yet
  runtime::Counter& plates_captured_;  // KeyerPlate requests completed
  runtime::Counter& plate_saves_failed_;  // completed plates that could not be kept in plate_dir
  runtime::Counter& controls_rejected_;
  runtime::Counter& commands_rejected_;
};

}  // namespace studio::capture::node

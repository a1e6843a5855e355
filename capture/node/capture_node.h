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
// The loop thread of runtime::ServiceLoop (runtime/service_loop.h) takes studio/camera/control
// and studio/capture/command: CameraControl for an allow-listed GenICam feature (Gain,
// ExposureTime, Focus, Zoom, Iris, BalanceRatioRed, BalanceRatioBlue) is applied through
// FrameSource::set_feature and the read-back value is published in CameraState; ImageRate and
// ImageRaw are the node's own pseudo-features; KeyerPlate (keyer/keyer.h) captures a clean plate
// for an in-process difference key (ignored with masks: false: the keyer node honours it then).
// CaptureCommand schedules start/stop per camera. Each camera's capture thread is a loop thread
// (camera_worker.h). The calibration of every camera (rig file, else the source's own) is published
// on studio/camera/calibration (transient-local) at start.
//
// Counters: masks_published, images_published, frames_captured, frames_recorded, frames_dropped,
// frames_unkeyed, plates_captured, plate_saves_failed; controls_rejected and commands_rejected
// (totals of their reasons: controls_rejected_<reason>, commands_rejected_<reason>).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_clock.h"
#include "capture/frame_source.h"
#include "capture/freed_listener.h"
#include "capture/lens_calibration.h"
#include "core/camera.h"
#include "core/mask_codec.h"
#include "keyer/keyer_options.h"
#include "runtime/service.h"

namespace studio::capture::node {

struct CameraSetup {
  std::string id;
  std::unique_ptr<FrameSource> source;
  std::optional<Camera> calibration;
  TrackedSource* tracked = nullptr;  // `source` itself when the camera is Free-D tracked
  bool report_tracker = false;       // this camera counts its listener's packets
  std::optional<LensTableOptions> lens_table;  // a fixed camera's zoom/focus -> intrinsics
  // What the camera model adds between the exposure instant and delivery (a simulated camera's
  // read-out: physics, reported apart from our cost, capture_stages.h); 0 for real cameras.
  int64_t modelled_readout_ns = 0;
};

struct CaptureNodeOptions {
  FrameClock clock;
  std::string takes_dir = "takes";
  std::size_t queue_frames = 50;
  int sync_interval_ms = 1000;  // recorder: fdatasync at least this often
  double disk_mb_s = 0;         // the takes disk's sustained write rate; 0 = measure at start
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

// The node, built from its options (cameras and sources already made by the config reader).
Expected<std::unique_ptr<runtime::Node>> make_capture_node(CaptureNodeOptions options,
                                                           runtime::NodeContext& context);

// service_main's definition of the capture service (name "capture"; capture_config.cc).
runtime::ServiceDefinition capture_service_definition();

}  // namespace studio::capture::node

#pragma once
// capture.yaml (the node's own keys; the common keys are read by runtime::service_main):
//
//   clock: {fps: 25, epoch_ns: 0}      # studio clock (DESIGN §5); or period_ns instead of fps
//   takes_dir: takes                   # takes/<take>/<camera_id>/ (relative to this file)
//   rig: rig.yaml                      # optional: calibrations to publish (else the source's own)
//   keyer: keyer.yaml                  # optional: keyer options (keyer/keyer.example.yaml)
//   image: {rate: 5, quality: 85, raw: false}   # latest-image service: Hz, JPEG quality, raw RGB8
//   masks: true                        # false: no keying here (studio-keyer --config keys the
//                                      # raw images; image: {rate: 1000, raw: true} sends every frame)
//   recorder: {queue_frames: 50}       # frames buffered between capture and disk
//   state_period: 1.0                  # seconds between CameraState samples
//   cameras:
//     - id: cam0
//       source: {type: sim, ring: 6, index: 0, width: 704, height: 576}   # simulated ring camera
//                 # motion: arm_swing (sim::Motion by name; default sequence), swing_peak_speed
//     - id: cam1
//       source: {type: files, path: DIR, fps: 25, loop: true}            # image folder replay
//     - id: cam2
//       source: {type: aravis, device: ID, pixel_format: BayerRG8, fps: 25, trigger: line}
//
// Errors are one line "file:line: field: problem".

#include <string>

#include "capture_node.h"
#include "yaml_io/node.h"

namespace studio::capture::node {

extern const char kConfigHelp[];

Expected<CaptureNodeOptions> read_capture_config(yaml::MapReader& config);

}  // namespace studio::capture::node

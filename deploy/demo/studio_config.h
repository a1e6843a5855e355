#pragma once
// What the demo probe needs to know about the studio it watches, read from the very capture
// configs the services run with (deploy/examples/studio/capture-*.yaml), so that the probe's
// truth and the cameras agree without a number written twice:
//   - the studio clock (clock: {fps, epoch_ns} or period_ns; defaults as studio-capture's);
//   - the camera ids, and whether each is a simulated camera (source type sim).
// The simulated cameras' geometry is NOT derived here: the probe takes it from the calibrations
// the capture services publish on studio/camera/calibration (exactly the cameras they render),
// and the scene (actor, seed, realism knobs) from capture::SimSourceOptions's defaults, which is
// what capture_config.cc gives every sim source.

#include <cstdint>
#include <string>
#include <vector>

#include "capture/frame_clock.h"
#include "core/error.h"

namespace studio::demo {

struct StudioConfig {
  capture::FrameClock clock;
  std::vector<std::string> camera_ids;  // in the order of the config files given
  std::vector<bool> simulated;          // per camera: source type sim
  bool all_simulated() const;
};

// Reads every file (one or more capture configs); all must agree on the clock. One clear line
// naming the file on error.
Expected<StudioConfig> read_studio_config(const std::vector<std::string>& capture_configs);

}  // namespace studio::demo

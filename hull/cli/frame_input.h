#pragma once
// Where `studio-hull offline` gets each frame's silhouettes from (DESIGN §4, §6):
//
// - a mask folder: DIR/<camera_id>.png (one frame) or DIR/<frame>/<camera_id>.png (a sequence),
//   0 = background, non-zero = actor;
// - a recorded take: DIR/<camera_id>/ as written by the capture recorder (capture/take.h:
//   frames.raw + index), keyed on the fly with the keyer library (keyer/keyer.h). Frames are
//   matched across cameras by their recorded frame number; the index is used when it is readable,
//   a scan of frames.raw otherwise. A camera whose folder holds per-frame calibration (a Free-D
//   tracked camera) is cut with its calibration of each frame (id and size from the rig), and
//   every selected frame must have one.
//
// Both check everything a frame needs before any work where it is cheap (a camera without a mask
// or recording, a frame one camera lacks) and, while loading, every mask or frame against its
// camera's size. Every error is one line naming the file, the camera and the frame.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/run_mask.h"
#include "keyer/keyer_options.h"

namespace studio::hull::cli {

struct FrameRange {
  long first = 0, last = 0;  // inclusive
};

// Milliseconds spent by one load, by stage.
struct LoadTimes {
  double read = 0;  // reading PNGs or take frames
  double key = 0;   // keying (takes only)
};

class FrameInput {
 public:
  virtual ~FrameInput() = default;
  // Frame names in order: "" for the single frame of a one-frame mask folder, otherwise the
  // decimal frame number (the output file's stem).
  const std::vector<std::string>& frames() const { return frames_; }
  bool keyed() const { return keyed_; }
  // The silhouettes of frame k, one per camera in rig order, into `masks`. Calls with different
  // `slot`s (0 .. slots-1 given at opening) may run concurrently.
  virtual Expected<void> load(std::size_t k, int slot, std::vector<RunMask>& masks,
                              LoadTimes& times) = 0;
  // Camera c (rig order) as it was at frame k when the input records per-frame calibration (a
  // tracked camera's take: capture/take_calibration.h), else nullptr: the rig's camera.
  virtual const Camera* camera(std::size_t k, std::size_t c) const {
    (void)k, (void)c;
    return nullptr;
  }

 protected:
  std::vector<std::string> frames_;
  bool keyed_ = false;
};

Expected<std::unique_ptr<FrameInput>> open_mask_folder(const std::string& dir,
                                                       const std::vector<Camera>& cameras,
                                                       std::optional<FrameRange> range);

Expected<std::unique_ptr<FrameInput>> open_take(const std::string& dir,
                                                const std::vector<Camera>& cameras,
                                                std::optional<FrameRange> range,
                                                const keyer::KeyerOptions& key, int slots);

// The cameras a take was recorded with: the `calibration:` of each DIR/<camera_id>/take.yaml
// (the camera's calibration when its take began), in camera id order. Errors, one line each:
// not a folder, no camera folder, an unreadable take.yaml, a camera recorded without
// calibration (then a rig file is needed), a calibration whose id is not its folder's.
Expected<std::vector<Camera>> cameras_of_take(const std::string& dir);

}  // namespace studio::hull::cli

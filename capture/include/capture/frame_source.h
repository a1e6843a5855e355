#pragma once
// The one interface every camera source implements (libcamera's lesson: a fake camera behind the
// same interface as real ones). Implementations: simulated studio, Aravis (GenICam GigE Vision /
// USB3 Vision), file replay (a recorded take or an image folder), each optionally carrying
// per-frame calibration (Free-D tracked cameras).
//
// Contract
// - start() then next() repeatedly from ONE thread (the capture loop); stop() may be called from
//   another thread and makes a blocked next() return promptly.
// - next(timeout) returns the next frame, std::nullopt when none arrived within `timeout`, or an
//   Error when the source failed; a source that can recover (a camera unplugged and back) keeps
//   returning nullopt while it retries, reports `connected = false` in stats(), and resumes.
// - Frame numbers follow DESIGN §5 (capture/frame_clock.h): the source stamps capture_ns from
//   the camera's timestamp (or the arrival time) and frame = clock.frame_at(capture_ns).
// - Features are GenICam-named ("Gain", "ExposureTime", "Focus", "Zoom", "Iris", ...);
//   set_feature() applies the value clamped to the feature's range and returns the value read
//   back from the device.

#include <chrono>
#include <functional>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"

namespace studio::capture {

// Where a source's capture_ns (and so its frame numbers) come from; CameraState reports it.
//   camera:       the camera's own timestamp (GenICam Timestamp, latched to the host clock)
//   camera_ptp:   the camera's timestamp, PTP-synchronised (already on the studio clock)
//   host_arrival: the host clock when the frame arrived (the fallback: jitter of the transport)
//   studio_clock: synthesised on the studio clock (simulated camera, file replay)
enum class TimeSource { host_arrival, camera, camera_ptp, studio_clock };

struct Frame {
  uint64_t frame = 0;       // studio frame number (DESIGN §5)
  int64_t capture_ns = 0;   // CLOCK_REALTIME of the exposure
  Image<Rgb8> image;        // always RGB8 here: Mono8 and Bayer are converted by the source
  // Per-frame calibration of a tracked (moving / zooming) camera; nullopt for fixed cameras.
  std::optional<Camera> calibration;
};

struct Feature {
  std::string name;
  double value = 0;
  double min = 0;
  double max = 0;
  bool writable = false;
};

struct SourceStats {
  uint64_t frames = 0;       // delivered by next()
  uint64_t drops = 0;        // frames lost before delivery (buffer underrun, incomplete, missed)
  uint64_t reconnects = 0;   // times the device came back after a loss
  bool connected = true;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual const std::string& id() const = 0;
  virtual Expected<void> start() = 0;
  virtual void stop() = 0;
  virtual Expected<std::optional<Frame>> next(std::chrono::milliseconds timeout) = 0;
  virtual std::vector<Feature> features() const { return {}; }
  virtual Expected<double> set_feature(std::string_view name, double value) {
    return fail("camera " + id() + ": feature '" + std::string(name) + "' is not available");
  }
  virtual SourceStats stats() const = 0;
  virtual TimeSource time_source() const { return TimeSource::host_arrival; }

  // A source that synthesises its pictures (the simulated camera) can follow a tracked pose:
  // `pose(frame)` is called on the capture thread before frame `frame` is made and returns the
  // camera to make it with (nullopt: keep the previous one). Returns false when the source
  // cannot (real cameras: the tracker follows them, not the other way round).
  using PoseOfFrame = std::function<std::optional<Camera>(uint64_t frame)>;
  virtual bool follow_pose(PoseOfFrame pose) {
    (void)pose;
    return false;
  }
};

}  // namespace studio::capture

#pragma once
// Remote zoom and focus on a FIXED camera (issue 17 item 2): the calibration describes the lens
// as it was when the camera was calibrated. When the Zoom or Focus feature changes:
//   - with a lens table (capture/freed.h LensTable; its zoom/focus are the feature values times
//     `feature_scale`, rounded) the intrinsics follow: new K and radial terms, the same pose;
//   - without one the calibration is invalid (the hull must leave the camera out) until the
//     features return to their calibrated values or the camera is recalibrated.
// Pure and single-threaded (the capture node calls it under its camera's lock).

#include <optional>
#include <string>
#include <string_view>

#include "capture/freed.h"
#include "core/camera.h"

namespace studio::capture {

struct LensTableOptions {
  LensTable table;
  double feature_scale = 1;  // table counts per feature unit
};

class LensCalibration {
 public:
  // `calibrated`: the camera's calibration (nullopt: none, nothing to follow); zoom/focus: the
  // feature values it was calibrated at (NaN when the source has no such feature).
  LensCalibration(std::optional<Camera> calibrated, std::optional<LensTableOptions> table,
                  double zoom, double focus);

  struct Change {
    bool republish = false;  // the intrinsics changed: publish camera()
    bool validity_changed = false;
  };
  // A read-back value of a feature; only Zoom and Focus matter.
  Change on_feature(std::string_view name, double value);

  const std::optional<Camera>& camera() const { return camera_; }
  bool valid() const { return problem_.empty(); }
  const std::string& problem() const { return problem_; }  // "" when valid

 private:
  std::optional<Camera> calibrated_, camera_;
  std::optional<LensTableOptions> table_;
  double zoom0_, focus0_, zoom_, focus_;
  std::string problem_;
};

}  // namespace studio::capture

#include "capture/lens_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace studio::capture {
namespace {

uint32_t counts(double value, double scale) {
  if (!std::isfinite(value)) return 0;
  return uint32_t(std::clamp(std::lround(value * scale), 0l, long(0xFFFFFF)));
}

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace

LensCalibration::LensCalibration(std::optional<Camera> calibrated,
                                 std::optional<LensTableOptions> table, double zoom, double focus)
    : calibrated_(std::move(calibrated)),
      camera_(calibrated_),
      table_(std::move(table)),
      zoom0_(zoom),
      focus0_(focus),
      zoom_(zoom),
      focus_(focus) {}

LensCalibration::Change LensCalibration::on_feature(std::string_view name, double value) {
  Change c;
  if (name == "Zoom")
    zoom_ = value;
  else if (name == "Focus")
    focus_ = value;
  else
    return c;
  if (!calibrated_) return c;
  const bool was_valid = valid();
  if (table_) {
    const LensSample s = table_->table.at(counts(zoom_, table_->feature_scale),
                                          counts(focus_, table_->feature_scale));
    Camera cam = *camera_;
    cam.intrinsics.fx = s.fx;
    cam.intrinsics.fy = s.fy;
    cam.intrinsics.cx = s.cx;
    cam.intrinsics.cy = s.cy;
    cam.distortion = Distortion::radial(s.rd3, s.rd5);
    const Intrinsics& o = camera_->intrinsics;
    c.republish = o.fx != s.fx || o.fy != s.fy || o.cx != s.cx || o.cy != s.cy ||
                  camera_->distortion.model != Distortion::Model::radial ||
                  camera_->distortion.rd3 != s.rd3 || camera_->distortion.rd5 != s.rd5;
    camera_ = std::move(cam);
  } else if (same(zoom_, zoom0_) && same(focus_, focus0_)) {
    problem_.clear();
  } else {
    char text[160];
    std::snprintf(text, sizeof text,
                  "%s moved to %g without a lens table: calibration invalid until recalibrated",
                  std::string(name).c_str(), value);
    problem_ = text;
  }
  c.validity_changed = was_valid != valid();
  return c;
}

}  // namespace studio::capture

#pragma once
// Calibration observations: which camera saw which target point where, frame by frame
// (DESIGN §4 observations.yaml, held in memory).
//
// A frame is one synchronous instant; its placement says what is known about the target pose:
// - origin: the target lies on the floor at the studio origin and fixes the studio frame: target
//   point 0 at (0,0,0), target x along studio +x, target y along studio +z, its face up (+y).
// - floor:  the target lies on the floor elsewhere: y = 0 and no tilt about x or z (3 dof).
// - free:   the target is anywhere (6 dof).
// A held-out frame is left out of the solve and scored after it (TCSVT 2004 §IV-A: "also on
// images not used for the calibration").

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::calibrate {

enum class Placement { origin, floor, free };
const char* to_string(Placement placement);
Expected<Placement> parse_placement(const std::string& text);

struct PointObservation {
  int id = 0;             // target point id (target.h)
  Eigen::Vector2d pixel;  // observed (distorted) pixel
};

struct View {
  std::string camera_id;
  std::vector<PointObservation> points;
};

struct FrameObservations {
  std::string id;
  Placement placement = Placement::free;
  bool holdout = false;
  std::vector<View> views;
};

struct CameraInfo {
  std::string id;
  int width = 0;   // 0 = unknown (estimated from the observations' extent)
  int height = 0;
};

struct Observations {
  std::vector<CameraInfo> cameras;
  std::vector<FrameObservations> frames;

  // Checks ids (unique, known cameras), point ids < point_count, finite pixels, at most one
  // origin frame; one line naming the frame/camera on failure.
  Expected<void> validate(int point_count) const;
  int camera_index(const std::string& id) const;  // -1 if unknown
  size_t observation_count() const;
};

}  // namespace studio::calibrate

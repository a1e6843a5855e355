#pragma once
// The cameras a hull frame is cut with (DESIGN §5: everything is stamped by frame). A fixed
// camera has one calibration, replaced when a new one arrives. A tracked camera (Free-D) sends one
// per frame, and the calibration of frame N+1 may arrive before the masks of frame N: its recent
// poses are kept by frame, so frame N is cut with the pose of frame N. Pure and single-threaded.
//
// Contract
// - CameraPoses(cameras): the rig's cameras, by index.
// - update(index, frame, tracked, camera): a calibration of camera `index`. Not tracked: replaces
//   the camera and forgets its history. Tracked: stored under `frame` (a second one for the same
//   frame replaces the first); only the newest `history` frames are kept. Either way the camera
//   becomes the latest one of that index.
// - camera_for(index, frame): the pose to cut `frame` with: the tracked camera's pose of that
//   frame; else its latest pose before `frame` (stale: the pose may be a frame off); else, when
//   every kept pose is newer than `frame`, the oldest kept (stale); a fixed camera: its latest
//   calibration (never stale).
// - set_valid(index, valid): the capture service's word on the calibration (CameraState
//   calibration_valid: false after a zoom/focus change without a lens table, or a silent
//   tracker); an invalid camera is left out of the cut rather than cutting with a wrong model.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "core/camera.h"

namespace studio::hull {

class CameraPoses {
 public:
  static constexpr std::size_t kDefaultHistory = 64;

  explicit CameraPoses(std::vector<Camera> cameras, std::size_t history = kDefaultHistory);

  std::size_t size() const { return cameras_.size(); }
  const Camera& latest(std::size_t index) const { return cameras_[index]; }
  void update(std::size_t index, uint64_t frame, bool tracked, Camera camera);

  struct Pose {
    const Camera* camera;
    bool stale;  // not the pose of the frame asked for
  };
  Pose camera_for(std::size_t index, uint64_t frame) const;
  void set_valid(std::size_t index, bool valid) { valid_[index] = valid; }
  bool valid(std::size_t index) const { return valid_[index]; }

 private:
  std::vector<bool> valid_;
  std::vector<Camera> cameras_;
  std::vector<std::deque<std::pair<uint64_t, Camera>>> tracked_;  // per camera, by frame
  std::size_t history_;
};

}  // namespace studio::hull

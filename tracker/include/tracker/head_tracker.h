#pragma once
// Head tracks over time (beyond the paper): identities, constant-velocity Kalman filtering and
// latency compensation.
//
// Each frame's detections (HeadSearch::find) are associated with the existing tracks greedily by
// distance to each track's prediction at the frame's capture time, within `gate`; an unmatched
// detection starts a track with a new id (ids are never reused); an unmatched track coasts on
// its prediction with its confidence multiplied by `coast_decay` per frame and is dropped after
// `max_missed` frames. Each track filters its head centre with a constant-velocity Kalman filter
// per axis (white-noise acceleration of `acceleration_sigma`, measurement noise
// `measurement_sigma`), so the published HeadPose carries a position, a velocity, a confidence
// and the capture time; HeadPose::predict() extrapolates to display time.
//
// When nothing is tracked (actor out of the volume, empty hull) primary() still answers: the
// last known head position, zero velocity, confidence 0, so a renderer keeps a sane eye point.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "core/error.h"
#include "tracker/head_search.h"

namespace studio::tracker {

struct HeadPose {
  uint32_t actor_id = 0;                               // track id; 0 = no track (fallback pose)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // studio frame, at capture_ns
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  double confidence = 0;                               // [0, 1]
  int64_t capture_ns = 0;  // capture time of the frame the pose is for (CLOCK_REALTIME)

  // Constant-velocity prediction at time t_ns (e.g. when the frame rendered from this eye point
  // reaches the projector), extrapolating at most max_horizon_s seconds (and never backwards).
  Eigen::Vector3d predict(int64_t t_ns, double max_horizon_s = 0.25) const;
};

struct HeadTrackerOptions {
  double measurement_sigma = 0.01;           // m, per axis, of one detection
  double acceleration_sigma = 2.0;           // m/s², white-noise acceleration of a head
  double gate = 0.5;                         // m, association distance
  int max_missed = 25;                       // frames a track coasts before it is dropped
  double coast_decay = 0.8;                  // confidence factor per missed frame
  Eigen::Vector3d rest_position{0, 1.7, 0};  // reported before anything was ever tracked

  Expected<void> validate() const;
};

class HeadTracker {
 public:
  static Expected<HeadTracker> create(const HeadTrackerOptions& options);

  // Advances to capture_ns with this frame's detections and returns the live tracks, most
  // confident first. A frame not later than the previous one is ignored (tracks unchanged).
  std::vector<HeadPose> update(std::span<const HeadDetection> detections, int64_t capture_ns);
  const std::vector<HeadPose>& poses() const { return poses_; }
  // The most confident live track, or the fallback pose (see above).
  HeadPose primary() const;

 private:
  struct Track {
    uint32_t id;
    Eigen::Matrix<double, 2, 3> state;  // rows: position, velocity; columns: x, y, z
    Eigen::Matrix2d cov;                // shared by the three axes (same noise model)
    double confidence;
    int missed;
  };
  explicit HeadTracker(const HeadTrackerOptions& o)
      : options_(o), last_position_(o.rest_position) {}
  void predict(Track& t, double dt) const;
  void correct(Track& t, const Eigen::Vector3d& z) const;
  Track start(const HeadDetection& d);

  HeadTrackerOptions options_;
  std::vector<Track> tracks_;
  std::vector<HeadPose> poses_;
  uint32_t next_id_ = 1;
  int64_t last_ns_ = 0;
  bool started_ = false;
  Eigen::Vector3d last_position_;
};

}  // namespace studio::tracker

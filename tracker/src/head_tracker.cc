#include "tracker/head_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::tracker {

Eigen::Vector3d HeadPose::predict(int64_t t_ns, double max_horizon_s) const {
  const double dt = std::clamp(double(t_ns - capture_ns) * 1e-9, 0.0, std::max(0.0, max_horizon_s));
  return position + dt * velocity;
}

Expected<void> HeadTrackerOptions::validate() const {
  if (!(measurement_sigma > 0) || !std::isfinite(measurement_sigma))
    return fail("tracker: measurement_sigma must be positive");
  if (!(acceleration_sigma > 0) || !std::isfinite(acceleration_sigma))
    return fail("tracker: acceleration_sigma must be positive");
  if (!(gate > 0) || !std::isfinite(gate)) return fail("tracker: gate must be positive");
  if (max_missed < 0) return fail("tracker: max_missed must be >= 0");
  if (!(coast_decay >= 0 && coast_decay <= 1))
    return fail("tracker: coast_decay must be in [0, 1]");
  if (!rest_position.allFinite()) return fail("tracker: rest_position must be finite");
  return {};
}

Expected<HeadTracker> HeadTracker::create(const HeadTrackerOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  return HeadTracker(options);
}

void HeadTracker::predict(Track& t, double dt) const {
  Eigen::Matrix2d F;
  F << 1, dt, 0, 1;
  const double q = options_.acceleration_sigma * options_.acceleration_sigma;
  Eigen::Matrix2d Q;
  Q << dt * dt * dt * dt / 4, dt * dt * dt / 2, dt * dt * dt / 2, dt * dt;
  t.state = F * t.state;
  t.cov = F * t.cov * F.transpose() + q * Q;
}

void HeadTracker::correct(Track& t, const Eigen::Vector3d& z) const {
  const double r = options_.measurement_sigma * options_.measurement_sigma;
  const double s = t.cov(0, 0) + r;
  const Eigen::Vector2d k = t.cov.col(0) / s;
  const Eigen::RowVector3d innovation = z.transpose() - t.state.row(0);
  t.state += k * innovation;
  t.cov -= k * t.cov.row(0);
}

HeadTracker::Track HeadTracker::start(const HeadDetection& d) {
  Track t;
  t.id = next_id_++;
  t.state.row(0) = d.position.transpose();
  t.state.row(1).setZero();
  const double r = options_.measurement_sigma * options_.measurement_sigma;
  t.cov << r, 0, 0, 1.0;  // velocity unknown: 1 m/s standard deviation
  t.confidence = d.confidence;
  t.missed = 0;
  return t;
}

std::vector<HeadPose> HeadTracker::update(std::span<const HeadDetection> detections,
                                          int64_t capture_ns) {
  if (started_ && capture_ns <= last_ns_) return poses_;
  const double dt = started_ ? double(capture_ns - last_ns_) * 1e-9 : 0.0;
  started_ = true;
  last_ns_ = capture_ns;
  for (Track& t : tracks_) predict(t, dt);

  // Greedy association by distance to the prediction.
  struct Pair {
    double d;
    std::size_t track, det;
  };
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < tracks_.size(); ++i)
    for (std::size_t j = 0; j < detections.size(); ++j) {
      const double d = (detections[j].position - tracks_[i].state.row(0).transpose()).norm();
      if (d < options_.gate) pairs.push_back({d, i, j});
    }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<bool> track_used(tracks_.size(), false), det_used(detections.size(), false);
  for (const Pair& p : pairs) {
    if (track_used[p.track] || det_used[p.det]) continue;
    track_used[p.track] = det_used[p.det] = true;
    Track& t = tracks_[p.track];
    correct(t, detections[p.det].position);
    t.confidence = detections[p.det].confidence;
    t.missed = 0;
  }
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    if (track_used[i]) continue;
    tracks_[i].missed += 1;
    tracks_[i].confidence *= options_.coast_decay;
    tracks_[i].state.row(1) *= options_.coast_decay;  // a lost head stops, it does not fly off
  }
  std::erase_if(tracks_, [&](const Track& t) { return t.missed > options_.max_missed; });
  for (std::size_t j = 0; j < detections.size(); ++j)
    if (!det_used[j]) tracks_.push_back(start(detections[j]));

  poses_.clear();
  for (const Track& t : tracks_) {
    HeadPose p;
    p.actor_id = t.id;
    p.position = t.state.row(0).transpose();
    p.velocity = t.state.row(1).transpose();
    p.confidence = t.confidence;
    p.capture_ns = capture_ns;
    poses_.push_back(p);
  }
  std::stable_sort(poses_.begin(), poses_.end(), [](const HeadPose& a, const HeadPose& b) {
    return a.confidence > b.confidence || (a.confidence == b.confidence && a.actor_id < b.actor_id);
  });
  if (!poses_.empty()) last_position_ = poses_.front().position;
  return poses_;
}

HeadPose HeadTracker::primary() const {
  if (!poses_.empty()) return poses_.front();
  HeadPose p;
  p.position = last_position_;
  p.capture_ns = last_ns_;
  return p;
}

}  // namespace studio::tracker

#pragma once
// The eye a projector frame is drawn from (issue 15 item 3): the followed actor's head while its
// pose is fresh (younger than timeout_s), else the last eye that gave a picture (the default eye
// until one did). A head pose that times out is dropped once and reported (went_stale), so the
// projection keeps showing the scene from the last good eye. Times: seconds, any monotonic clock.

#include <Eigen/Core>
#include <optional>

namespace studio::projector {

class EyeSource {
 public:
  EyeSource(const Eigen::Vector3d& default_eye, double timeout_s)
      : last_good_(default_eye), timeout_s_(timeout_s) {}

  void head(const Eigen::Vector3d& position, double now_s) { head_ = Head{position, now_s}; }
  // The eye at now_s; *went_stale is set when the head pose timed out at this call.
  Eigen::Vector3d eye(double now_s, bool* went_stale = nullptr) {
    if (went_stale) *went_stale = false;
    if (head_) {
      if (now_s - head_->at_s < timeout_s_) return head_->position;
      head_.reset();
      if (went_stale) *went_stale = true;
    }
    return last_good_;
  }
  // A frame was drawn from `eye`.
  void good(const Eigen::Vector3d& eye) { last_good_ = eye; }
  const Eigen::Vector3d& last_good() const { return last_good_; }

 private:
  struct Head {
    Eigen::Vector3d position;
    double at_s;
  };
  std::optional<Head> head_;
  Eigen::Vector3d last_good_;
  double timeout_s_;
};

}  // namespace studio::projector

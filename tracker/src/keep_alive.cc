#include "tracker/keep_alive.h"

namespace studio::tracker {

KeepAlive::KeepAlive(const HeadTrackerOptions& filter, double rate_hz, const HeadPose& rest,
                     Clock::time_point now)
    : filter_(filter),
      dt_(1.0 / rate_hz),
      period_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(dt_))),
      pose_(rest),
      source_arrival_(now),
      last_publish_(now) {}

void KeepAlive::frame(const HeadPose& pose, uint64_t frame, Clock::time_point arrival) {
  pose_ = pose;
  frame_ = frame;
  coasted_ = 0;
  have_source_ = true;
  source_ns_ = pose.capture_ns;
  source_arrival_ = arrival;
  last_publish_ = arrival;
}

HeadPose KeepAlive::tick(Clock::time_point now) {
  HeadPose p = pose_;
  ++coasted_;
  if (coasted_ > filter_.max_missed || p.confidence <= 0) {
    p.velocity.setZero();
    p.confidence = 0;
  } else {
    p.position += p.velocity * dt_;
    p.velocity *= filter_.coast_decay;
    p.confidence *= filter_.coast_decay;
  }
  if (have_source_)
    p.capture_ns =
        source_ns_ +
        std::chrono::duration_cast<std::chrono::nanoseconds>(now - source_arrival_).count();
  pose_ = p;
  last_publish_ = now;
  return p;
}

}  // namespace studio::tracker

#pragma once
// What the tracker service publishes when no frame arrives (the keep-alive of studio/actor/head):
// the last published primary pose, coasting. Pure (no DDS, no clock reads: times are passed in).
//
// Contract
// - frame(pose, frame, arrival): a real frame's primary pose was published; it was captured at
//   pose.capture_ns (the source's clock) and arrived at `arrival` (steady clock). Coasting starts
//   over from it.
// - due(): the time the next keep-alive is due: 1/rate after the last published pose (real or
//   keep-alive).
// - tick(now): the next keep-alive pose, published at `now`. Each tick advances the position by the
//   velocity over one tick (1/rate) and multiplies velocity and confidence by coast_decay; after
//   max_missed ticks (or once the confidence is 0) velocity and confidence are 0 and the position
//   stays (HeadTracker's coasting, per tick instead of per frame). Its capture_ns is the last real
//   frame's capture_ns plus the time elapsed since that frame arrived (the instant the pose is
//   predicted for, on the source's clock); before any real frame it keeps the rest pose's.
//   Keep-alives never enter the HeadTracker, so the next real frame is filtered against the last
//   real one.
// - frame_number(): the source frame of the last published pose (keep-alives repeat it);
//   lost(): its confidence is 0 (no head tracked).

#include <chrono>
#include <cstdint>

#include "tracker/head_tracker.h"

namespace studio::tracker {

class KeepAlive {
 public:
  using Clock = std::chrono::steady_clock;

  // rate_hz > 0; `rest` is published until the first frame (HeadTracker::primary() of a new
  // tracker); `now` starts the first period.
  KeepAlive(const HeadTrackerOptions& filter, double rate_hz, const HeadPose& rest,
            Clock::time_point now);

  void frame(const HeadPose& pose, uint64_t frame, Clock::time_point arrival);
  Clock::time_point due() const { return last_publish_ + period_; }
  HeadPose tick(Clock::time_point now);

  const HeadPose& pose() const { return pose_; }
  uint64_t frame_number() const { return frame_; }
  bool lost() const { return pose_.confidence <= 0; }

 private:
  HeadTrackerOptions filter_;
  double dt_;  // seconds per tick
  Clock::duration period_;
  HeadPose pose_;  // last published
  uint64_t frame_ = 0;
  int coasted_ = 0;
  bool have_source_ = false;
  int64_t source_ns_ = 0;  // capture_ns of the last real frame
  Clock::time_point source_arrival_;
  Clock::time_point last_publish_;
};

}  // namespace studio::tracker

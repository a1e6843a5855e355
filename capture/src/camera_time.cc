#include "capture/camera_time.h"

#include <algorithm>

namespace studio::capture {

void CameraTimeLatch::latch(int64_t device_ns, int64_t host_before_ns, int64_t host_after_ns) {
  if (device_ns <= 0 || host_after_ns < host_before_ns) return;
  latched_ = host_before_ns + (host_after_ns - host_before_ns) / 2 - device_ns;
}

std::optional<int64_t> CameraTimeLatch::offset() const {
  std::optional<int64_t> best = latched_;
  for (int64_t d : arrivals_)
    if (!best || d < *best) best = d;
  return best;
}

std::optional<int64_t> CameraTimeLatch::frame(int64_t device_ns, int64_t arrival_ns) {
  if (device_ns <= 0) return std::nullopt;
  arrivals_.push_back(arrival_ns - device_ns);
  while (arrivals_.size() > window_) arrivals_.pop_front();
  // The latch, when there is one, is a lower bound too: a frame cannot arrive before it was
  // stamped, so an arrival difference below the latched offset means the latch is stale (the
  // camera restarted its counter): the frames win.
  return device_ns + *offset();
}

}  // namespace studio::capture

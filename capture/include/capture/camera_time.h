#pragma once
// Camera time latched to the host clock (issue 17 item 4): a camera stamps each frame with its own
// counter (GenICam Timestamp, ns since the camera's power-up); the host clock (CLOCK_REALTIME, the
// studio clock's base, DESIGN §5) is the one frame numbers are counted in. The latch maps one to
// the other:
//   host_ns = device_ns + offset
// seeded by a GenICam latch (TimestampLatch / GevTimestampControlLatch executed between two host
// clock reads: offset = host midpoint - latched value) when the camera has one, and refined by
// every frame: a frame's host arrival minus its device stamp is offset + transport delay >= offset,
// so the smallest such difference over the last `window` frames is the offset plus the shortest
// delay seen (typically tens of microseconds on GigE). Frames keep the camera's exact spacing;
// the network's jitter no longer moves them across a frame boundary.
// A camera whose timestamps are 0 (none) leaves the latch unseeded: callers fall back to host
// arrival time (the documented fallback) and report it (capture::TimeSource).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

namespace studio::capture {

class CameraTimeLatch {
 public:
  explicit CameraTimeLatch(std::size_t window = 128) : window_(window ? window : 1) {}

  // A latch of the camera's clock: its value `device_ns` was read between host times
  // host_before_ns and host_after_ns.
  void latch(int64_t device_ns, int64_t host_before_ns, int64_t host_after_ns);
  // One frame: its device stamp and host arrival. Returns its host time (device stamp + offset),
  // or nullopt when the camera gives no stamp (device_ns == 0).
  std::optional<int64_t> frame(int64_t device_ns, int64_t arrival_ns);

  bool seeded() const { return latched_.has_value() || !arrivals_.empty(); }
  std::optional<int64_t> offset() const;
  void reset() {
    latched_.reset();
    arrivals_.clear();
  }

 private:
  std::size_t window_;
  std::optional<int64_t> latched_;  // from latch()
  std::deque<int64_t> arrivals_;    // arrival - device stamp of the last `window` frames
};

}  // namespace studio::capture

#pragma once
// Studio-wide frame numbering (DESIGN §5): every capture server names the same instant with the
// same number without talking, because cameras are genlocked and the epoch and period come from
// the studio config:
//   frame = floor((capture_ns - epoch_ns) / period_ns)
// A capture command names a future frame number; every server starts (and stops) recording at
// exactly that frame.
// Choose epoch_ns half a period before the genlock trigger instants, so that timestamp jitter
// (microseconds) never moves a frame across a boundary of the floor().

#include <cstdint>

namespace studio::capture {

struct FrameClock {
  int64_t epoch_ns = 0;
  int64_t period_ns = 40'000'000;  // 25 fps

  // Frames before the epoch clamp to 0.
  uint64_t frame_at(int64_t capture_ns) const {
    if (capture_ns <= epoch_ns) return 0;
    return uint64_t((capture_ns - epoch_ns) / period_ns);
  }
  // Start of frame `frame`.
  int64_t time_of(uint64_t frame) const { return epoch_ns + int64_t(frame) * period_ns; }
  bool valid() const { return period_ns > 0; }
};

}  // namespace studio::capture

#pragma once
// Where a frame's time goes inside a capture server, from its capture instant to its mask on the
// wire (issue 20: the live pipeline's latency per stage), published as status gauges (ms, a
// running mean over about the last 20 frames of the server's cameras, like the hull's
// HullStages; wall time, so preemption by other work counts where it happens):
//   stage_readout_model_ms  what the camera model itself adds between the exposure instant and
//                           the frame reaching the host (a simulated camera's `readout_us`: the
//                           rest of the exposure, read-out, link transfer); physics, not our
//                           cost; 0 for real cameras (their delay is all in stage_grab_late_ms)
//   stage_grab_late_ms      capture_ns + the modelled read-out -> the grab thread holds the frame
//                           (a render not finished in time, the thread's wake-up; for a real
//                           camera its whole read-out, transfer and driver)
//   stage_key_ms            the in-process key (keyer::PlateKeyer::frame)
//   stage_code_ms           mask codec + AlphaMask sample
//   stage_write_ms          the AlphaMask written (serialisation, the sends)
//   capture_to_mask_ms      capture_ns -> the mask written (every stage above; CLOCK_REALTIME)
// Thread-safe: every camera's grab thread adds to the same gauges.

#include <array>
#include <chrono>
#include <mutex>

#include "runtime/metrics.h"

namespace studio::capture::node {

class CaptureStages {
 public:
  enum Stage { readout_model, grab_late, key, code, write, capture_to_mask, kCount };

  explicit CaptureStages(runtime::Metrics& metrics) {
    static constexpr const char* kNames[kCount] = {"stage_readout_model_ms", "stage_grab_late_ms",
                                                   "stage_key_ms",           "stage_code_ms",
                                                   "stage_write_ms",         "capture_to_mask_ms"};
    for (int i = 0; i < kCount; ++i) gauges_[i] = &metrics.gauge(kNames[i]);
  }
  // One measurement of a stage, milliseconds.
  void add(Stage s, double ms) {
    std::lock_guard lock(mutex_);
    mean_[s] = seen_[s] ? mean_[s] + 0.05 * (ms - mean_[s]) : ms;
    seen_[s] = true;
    gauges_[s]->set(mean_[s]);
  }
  template <class Rep, class Period>
  void add(Stage s, std::chrono::duration<Rep, Period> d) {
    add(s, std::chrono::duration<double, std::milli>(d).count());
  }

 private:
  std::mutex mutex_;
  std::array<runtime::Gauge*, kCount> gauges_{};
  std::array<double, kCount> mean_{};
  std::array<bool, kCount> seen_{};
};

}  // namespace studio::capture::node

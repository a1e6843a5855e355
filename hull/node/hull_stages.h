#pragma once
// Where a frame's time goes inside the hull service, from its last mask to its last mesh
// (issue 20: the live pipeline's latency per stage), published as status gauges (ms, a running
// mean over about the last 20 frames, like the projector's FrameStages):
//   capture_to_mask_ms      the frame's capture_ns -> its last mask written by its capture server
//                           (source_timestamp): the capture stage as the hull sees it, free of
//                           any subscriber's own wake-up delay
//   stage_mask_delivery_ms  the frame's last mask: written by its capture server
//                           (source_timestamp) -> handed to the hull's handler (DDS transport,
//                           the loop's wake-up; CLOCK_REALTIME, same host)
//   stage_assembly_ms       the frame's first mask handled -> its last (the assembly's wait for
//                           the slowest capture server)
//   stage_queue_ms          last mask handled -> the frame's cut starts (other frames or work
//                           ahead of it on the loop thread; for a frame cut at its deadline
//                           without every mask, also the wait for the missing ones)
//   stage_cut_ms            visual hull + connected components
//   stage_mesh_ms           segment marching cubes, every actor
//   stage_refine_ms         exact crossings, every actor
//   stage_publish_ms        segments and meshes converted to samples and written
//   mask_to_mesh_ms         last mask handled -> last mesh written (the hull's share of the
//                           motion-to-photon latency)
// Loop thread only (gauges are atomics; the status thread reads them).

#include <array>
#include <chrono>

#include "runtime/metrics.h"

namespace studio::hull {

class HullStages {
 public:
  enum Stage {
    capture_to_mask,
    mask_delivery,
    assembly,
    queue,
    cut,
    mesh,
    refine,
    publish,
    mask_to_mesh,
    kCount
  };

  explicit HullStages(runtime::Metrics& metrics) {
    static constexpr const char* kNames[kCount] = {
        "capture_to_mask_ms", "stage_mask_delivery_ms", "stage_assembly_ms",
        "stage_queue_ms",     "stage_cut_ms",           "stage_mesh_ms",
        "stage_refine_ms",    "stage_publish_ms",       "mask_to_mesh_ms"};
    for (int i = 0; i < kCount; ++i) gauges_[i] = &metrics.gauge(kNames[i]);
  }
  // One measurement of a stage, milliseconds.
  void add(Stage s, double ms) {
    mean_[s] = seen_[s] ? mean_[s] + 0.05 * (ms - mean_[s]) : ms;
    seen_[s] = true;
    gauges_[s]->set(mean_[s]);
  }
  template <class Duration>
  void add(Stage s, Duration d) {
    add(s, std::chrono::duration<double, std::milli>(d).count());
  }

 private:
  std::array<runtime::Gauge*, kCount> gauges_{};
  std::array<double, kCount> mean_{};
  std::array<bool, kCount> seen_{};
};

}  // namespace studio::hull

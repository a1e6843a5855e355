#pragma once
// Where a projector frame's time goes, from the arrival of an actor mesh (the DDS handler) to the
// frame rendered with it, published as status gauges (ms, a running mean over about the last 20
// frames that had the stage; issue 15: "the per-stage breakdown says where the time goes"):
//   stage_wait_ms      mesh handed over by the handler -> the render thread takes it (the render
//                      thread was busy with the previous frame, its read-back or publish; late
//                      latching: the scene drawn ahead or the previous mesh's fit)
//   stage_motion_ms    the mesh's motion estimate (once per mesh, MaskPlanner::set_mesh; late
//                      latching: after the mesh's first frame, off its path, fit_pending with
//                      the velocity field it builds; with the fit thread, the fit's wall time
//                      there, at its lower priority, added when the render thread installs it)
//   stage_simplify_ms  the mask mesh simplified (once per mesh)
//   stage_latch_ms     late latching: the previous fit's velocities looked up for the new mesh's
//                      vertices (once per mesh, MaskPlanner::latch_mesh)
//   stage_ahead_ms     late latching: the next frame's scene drawn ahead after a frame (GL
//                      submission + flush; llvmpipe rasterises it while the thread waits), off
//                      the mesh's path except for the very first frame
//   stage_mask_ms      per frame: the masks moved forward to the display instant and grown
//   stage_draw_ms      per frame: GL commands for the scene and the masks (submission; late
//                      latching: the masks only)
//   stage_finish_ms    per frame: glFinish, i.e. llvmpipe rasterising the frame (late latching:
//                      the masks and what is left of the scene drawn ahead)
//   stage_readback_ms  per published frame: glReadPixels, blackout runs, thumbnail
//   stage_publish_ms   per published frame: the studio/projector/frame sample written
//   mesh_to_frame_ms   mesh arrival -> frame rendered (finished), frames with a new mesh
//   stage_present_ms   per frame with output: window: blit to the window and swap
//   stage_load_ms      scene_thread: per frame, the newest scene image loaded into the frame
//   scene_image_ms     scene_thread: an image drawn and read back (wall), on the scene thread
//   scene_image_age_ms scene_thread: the image a frame used, from its read-back to the frame done
// Each stage is added to from one thread only: scene_image_ms by the scene thread, the others
// by the render thread (gauges are atomics; the status thread reads them).

#include <array>
#include <chrono>
#include <ctime>
#include <optional>

#include "runtime/metrics.h"

namespace studio::projector {

class FrameStages {
 public:
  enum Stage {
    wait,
    motion,
    simplify,
    mask,
    draw,
    finish,
    readback,
    publish,
    mesh_to_frame,
    present,
    latch,
    ahead,
    load,
    scene_image,
    scene_age,
    kCount
  };

  explicit FrameStages(runtime::Metrics& metrics) {
    static constexpr const char* kNames[kCount] = {
        "stage_wait_ms",    "stage_motion_ms",  "stage_simplify_ms", "stage_mask_ms",
        "stage_draw_ms",    "stage_finish_ms",  "stage_readback_ms", "stage_publish_ms",
        "mesh_to_frame_ms", "stage_present_ms", "stage_latch_ms",    "stage_ahead_ms",
        "stage_load_ms",    "scene_image_ms",   "scene_image_age_ms"};
    for (int i = 0; i < kCount; ++i) gauges_[i] = &metrics.gauge(kNames[i]);
  }
  // One measurement of a stage, seconds.
  void add(Stage s, double seconds) {
    const double ms = seconds * 1e3;
    mean_[s] = seen_[s] ? mean_[s] + 0.05 * (ms - mean_[s]) : ms;
    seen_[s] = true;
    gauges_[s]->set(mean_[s]);
  }

 private:
  std::array<runtime::Gauge*, kCount> gauges_{};
  std::array<double, kCount> mean_{};
  std::array<bool, kCount> seen_{};
};

// The process's CPU time (every thread: llvmpipe's rasteriser threads, DDS, the render thread)
// per rendered frame, over windows of at least a second (gauge cpu_per_frame_ms).
class CpuPerFrame {
 public:
  // One frame rendered; the seconds of CPU per frame when a window closes.
  std::optional<double> frame_done() {
    const auto now = std::chrono::steady_clock::now();
    const double cpu = process_cpu_s();
    if (frames_ < 0) {  // the first frame opens the first window
      start_ = now;
      cpu_start_ = cpu;
      frames_ = 0;
      return std::nullopt;
    }
    ++frames_;
    if (now - start_ < std::chrono::seconds(1)) return std::nullopt;
    const double per_frame = (cpu - cpu_start_) / frames_;
    start_ = now;
    cpu_start_ = cpu;
    frames_ = 0;
    return per_frame;
  }

 private:
  static double process_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  }
  std::chrono::steady_clock::time_point start_;
  double cpu_start_ = 0;
  long frames_ = -1;
};

}  // namespace studio::projector

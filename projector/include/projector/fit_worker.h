#pragma once
// Late latching's motion fits on a thread of their own (issue 20: the fit off the render path).
//
// The projector's render thread latches each new actor mesh with the previous fit's velocities
// (mask_planner.h latch_mesh) and, in the synchronous form, fits the mesh's own motion after the
// mesh's first frame (fit_pending): on the demo's hull meshes ~10 ms of CPU, and on a shared
// 2-core machine ~40 ms of wall time, during which a newer mesh waits for the thread
// (stage_wait_ms) or is superseded. A FitWorker runs the fits instead: the render thread hands
// each latched mesh over (submit), keeps drawing, and installs the fits that finished at its next
// frame (take, then MaskPlanner::apply_fit). The worker's thread runs `nice_increment` below the
// process (a per-thread nice value, Linux); under a real-time process it runs time-sharing at the
// process's nice value + nice_increment (or, `realtime`, at real-time priority 1), so the render
// thread and llvmpipe's rasteriser keep the CPU they need and the fit takes what they leave.
//
// Newest wins: a mesh still waiting when a newer mesh of the same actor is submitted is dropped
// (counted, dropped()); the next fit is then against the last mesh fitted, over two mesh
// intervals, as in the synchronous form when a fit is deferred. A fit finishes late or not at
// all under load; the mesh latched meanwhile keeps the older velocities, whose age the margin
// counts (mask_margin.h velocity_age_s). Results come in the order fitted; the trackers (one per
// actor, MotionTracker) are the worker's alone.
//
// remove(actor) forgets an actor: its waiting mesh, its tracker, and any result not yet taken
// (also one being computed when it is called).

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "projector/motion_fit.h"

namespace studio::projector {

struct FitWorkerOptions {
  MotionOptions motion;
  // The fit thread's nice value above the process's (0..19; 0: the same priority as the caller).
  int nice_increment = 0;
  // Above 0 under a real-time caller (SCHED_FIFO/RR): false, the fit thread runs time-sharing at
  // the caller's nice value + nice_increment, sharing what the real-time threads leave with the
  // process's other time-sharing threads (the projector's scene thread); true, at the lowest
  // real-time priority (1): below the caller, above all time-sharing work — every mesh fitted,
  // but the scene thread then gets what the fits leave (BENCHMARKS.md, demo, session 18).
  bool realtime = false;
  Expected<void> validate() const;
};

class FitWorker {
 public:
  // Starts the thread. Errors: invalid options, no thread to be had.
  static Expected<std::unique_ptr<FitWorker>> create(const FitWorkerOptions& options);
  ~FitWorker();  // a fit in progress finishes, waiting meshes are dropped, the thread joined
  FitWorker(const FitWorker&) = delete;
  FitWorker& operator=(const FitWorker&) = delete;

  // The actor's newest mesh, to fit. True when it replaced one of that actor's meshes not yet
  // started (that one is dropped).
  bool submit(const std::string& actor, ActorMesh mesh);
  void remove(const std::string& actor);
  // The fits finished since the last call, oldest first.
  std::vector<FitResult> take();
  // Blocks until no mesh waits and no fit runs (tests; the projector never waits).
  void drain();
  std::uint64_t fitted() const;
  std::uint64_t dropped() const;
  // Empty when the thread lowered its priority as asked; else one line saying why not (e.g. a
  // seccomp filter denying setpriority), for the caller to log.
  std::string priority_note() const;

 private:
  explicit FitWorker(const FitWorkerOptions& options);
  void run();
  struct Job {
    std::string actor;
    std::uint64_t epoch = 0;  // the actor's epoch at submission (remove() starts a new one)
    ActorMesh mesh;
  };
  FitWorkerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  bool stop_ = false;
  bool busy_ = false;
  bool started_ = false;  // the thread has set its priority (priority_note_)
  std::string priority_note_;
  std::deque<Job> jobs_;  // at most one per actor
  std::map<std::string, std::uint64_t> epochs_;
  std::vector<FitResult> results_;
  std::uint64_t fitted_ = 0, dropped_ = 0;
  // The worker thread's alone: each actor's tracker and the epoch it belongs to.
  std::map<std::string, std::pair<std::uint64_t, MotionTracker>> trackers_;
  std::thread thread_;
};

}  // namespace studio::projector

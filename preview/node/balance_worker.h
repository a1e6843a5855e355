#pragma once
// The preview's colour balance (preview/rig_balance.h) pooled on a thread of its own: pooling a
// mesh costs 4-10 ms of CPU (BENCHMARKS.md), a stall the render thread should not take. One job
// at a time: a mesh handed over while the previous one is still being pooled is refused (the
// caller counts it); the render thread reads the latest estimate as a snapshot.
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/run_mask.h"
#include "preview/frame_images.h"
#include "preview/rig_balance.h"

namespace studio::preview {

class BalanceWorker {
 public:
  // One mesh's frame: the rig, the mesh, and per texturing camera its image and mask (copies).
  struct Job {
    std::map<std::string, Camera> rig;
    scene::ActorMesh mesh;
    std::vector<std::string> cameras;
    std::vector<FrameImage> images;
    std::vector<RunMask> masks;
  };

  // nice > 0: the worker thread yields the CPU to the rest (background work: the rig samples).
  explicit BalanceWorker(int nice = 0);
  ~BalanceWorker();  // finishes the job in hand, then joins
  BalanceWorker(const BalanceWorker&) = delete;
  BalanceWorker& operator=(const BalanceWorker&) = delete;

  // Hands a job over; false (nothing taken) while the previous one is still being pooled.
  bool submit(Job&& job);
  // The estimate after the last pooled job.
  BalanceSnapshot snapshot() const;
  // Waits until the job in hand (if any) is pooled (a run's end: its summary includes it).
  void wait_idle();
  // Forgets everything pooled (the cameras' colours were changed at the cameras): the snapshot
  // is an empty estimate (gains 1) at once; a job in hand is pooled into nothing.
  void restart();
  uint64_t pooled() const;  // jobs pooled so far

 private:
  void run();

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::optional<Job> job_;
  bool busy_ = false, stop_ = false, restart_ = false;
  uint64_t pooled_ = 0;
  RigBalance balance_;  // the worker thread's alone
  BalanceSnapshot snapshot_;
  std::thread thread_;  // last: started when everything above exists
};

}  // namespace studio::preview

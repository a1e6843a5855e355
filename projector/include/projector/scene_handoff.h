#pragma once
// Between the projector node's scene thread and its render thread (ProjectorNodeOptions::
// scene_thread): the newest scene image. The scene thread draws the scene from the eye expected
// when its image is shown, into a renderer on a display of its own, and publishes the image
// here; the render thread takes the newest one whenever it draws a frame — a new actor mesh's,
// at once — and puts the masks over it. So a mesh never waits for the scene to be drawn.
//
// A triple buffer: the writer fills its own slot (back()) and publish() makes it the newest;
// the reader's take() swaps in the newest published slot, which stays the reader's until its
// next take(). Neither side ever waits for the other's work (an index swap under a mutex). An
// image published and replaced before any take() saw it is counted (`skipped`).

#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

namespace studio::projector {

struct SceneImage {
  std::vector<std::uint8_t> rgba;  // the projector frame's scene, RGBA, bottom row first
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();  // drawn from (studio frame)
  std::chrono::steady_clock::time_point done;     // read back (complete) at
  bool from_cache = false;  // the static layer restored, not drawn
  bool held = false;        // restored beyond the bound (SceneCacheOptions::hold_frames)
  double shift_px = 0;      // the cached layer's displacement bound at `eye`
  std::uint64_t sequence = 0;  // 1, 2, ... in publish order (set by publish)
};

class SceneHandoff {
 public:
  // Writer: its slot, to fill.
  SceneImage& back() { return slots_[back_]; }
  // Writer: back() becomes the newest image; the writer gets another slot.
  void publish() {
    std::lock_guard lock(mutex_);
    slots_[back_].sequence = ++published_;
    if (fresh_) ++skipped_;  // the newest was never taken
    std::swap(back_, ready_);
    fresh_ = true;
    cv_.notify_all();
  }
  // Reader: the newest image (fresh: published since the previous take), or the one taken
  // before when none is newer; nullptr before the first publish.
  const SceneImage* take(bool* fresh = nullptr) {
    std::lock_guard lock(mutex_);
    if (fresh) *fresh = fresh_;
    if (fresh_) {
      std::swap(front_, ready_);
      fresh_ = false;
    }
    return slots_[front_].sequence > 0 ? &slots_[front_] : nullptr;
  }
  // Reader: waits up to `timeout` for a first image (or stop()); true when one is published.
  bool wait_first(std::chrono::steady_clock::duration timeout) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [this] { return published_ > 0 || stopped_; }) &&
           published_ > 0;
  }
  // Wakes wait_first() for good.
  void stop() {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    cv_.notify_all();
  }
  std::uint64_t published() const {
    std::lock_guard lock(mutex_);
    return published_;
  }
  std::uint64_t skipped() const {
    std::lock_guard lock(mutex_);
    return skipped_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  SceneImage slots_[3];
  int back_ = 0, ready_ = 1, front_ = 2;
  bool fresh_ = false;  // ready_ holds an image not yet taken
  bool stopped_ = false;
  std::uint64_t published_ = 0, skipped_ = 0;
};

}  // namespace studio::projector

#include "hull/camera_poses.h"

#include <algorithm>
#include <iterator>

namespace studio::hull {

CameraPoses::CameraPoses(std::vector<Camera> cameras, std::size_t history)
    : valid_(cameras.size(), true),
      cameras_(std::move(cameras)),
      tracked_(cameras_.size()),
      history_(std::max<std::size_t>(history, 1)) {}

void CameraPoses::update(std::size_t index, uint64_t frame, bool tracked, Camera camera) {
  auto& history = tracked_[index];
  if (tracked) {
    auto at = std::lower_bound(history.begin(), history.end(), frame,
                               [](const auto& e, uint64_t f) { return e.first < f; });
    if (at != history.end() && at->first == frame)
      at->second = camera;
    else
      history.insert(at, {frame, camera});
    while (history.size() > history_) history.pop_front();
  } else {
    history.clear();
  }
  cameras_[index] = std::move(camera);
}

CameraPoses::Pose CameraPoses::camera_for(std::size_t index, uint64_t frame) const {
  const auto& history = tracked_[index];
  if (history.empty()) return {&cameras_[index], false};
  auto after = std::upper_bound(history.begin(), history.end(), frame,
                                [](uint64_t f, const auto& e) { return f < e.first; });
  if (after == history.begin()) return {&history.front().second, true};
  const auto& [at, camera] = *std::prev(after);
  return {&camera, at != frame};
}

}  // namespace studio::hull

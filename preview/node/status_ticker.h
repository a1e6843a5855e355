#pragma once
// The preview's studio/service/status, as every service publishes it (runtime/status_publisher.h):
// service "preview", the config's instance, RUNNING (DEGRADED when the node says so) with its
// counters (meshes in, images in, requests, ...) once per `period`, STOPPING at the end. The
// preview is a window or a headless renderer, not a runtime::service_main loop, so its render
// loop calls tick() each frame.
#include <chrono>
#include <functional>

#include "runtime/service_loop.h"
#include "runtime/status_publisher.h"

namespace studio::preview {

class StatusTicker {
 public:
  static Expected<StatusTicker> create(runtime::NodeContext& context, runtime::Node& node,
                                       std::chrono::milliseconds period = std::chrono::seconds(1));
  // Publishes when `period` has passed since the last one (the first call publishes).
  void tick();
  // Publishes STOPPING (call before stopping the node).
  void stopping();
  // Called just before each publication (fills gauges that are derived on demand).
  void before_publish(std::function<void()> fill) { fill_ = std::move(fill); }

 private:
  StatusTicker(runtime::StatusPublisher publisher, runtime::Metrics& metrics, runtime::Node& node,
               std::chrono::milliseconds period)
      : publisher_(std::move(publisher)), metrics_(&metrics), node_(&node), period_(period) {}
  runtime::StatusPublisher publisher_;
  runtime::Metrics* metrics_;
  runtime::Node* node_;
  std::chrono::milliseconds period_;
  std::chrono::steady_clock::time_point next_{};
  std::function<void()> fill_;
};

}  // namespace studio::preview

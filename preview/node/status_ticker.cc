#include "status_ticker.h"

#include "core/log.h"

namespace studio::preview {

Expected<StatusTicker> StatusTicker::create(runtime::NodeContext& context, runtime::Node& node,
                                            std::chrono::milliseconds period) {
  auto p = runtime::StatusPublisher::create(context.participant, "preview", context.instance);
  if (!p) return std::unexpected(p.error());
  return StatusTicker(std::move(*p), context.metrics, node, period);
}

void StatusTicker::tick() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_) return;
  next_ = now + period_;
  if (fill_) fill_();
  const runtime::NodeHealth h = node_->health();
  const auto state = h.degraded ? studio_SERVICE_DEGRADED : studio_SERVICE_RUNNING;
  if (auto ok = publisher_.publish(state, h, metrics_->snapshot()); !ok)
    STUDIO_LOG(warn, "preview") << "status: " << ok.error().message;
}

void StatusTicker::stopping() {
  if (fill_) fill_();
  (void)publisher_.publish(studio_SERVICE_STOPPING, node_->health(), metrics_->snapshot());
}

}  // namespace studio::preview

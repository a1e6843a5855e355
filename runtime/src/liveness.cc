#include "runtime/liveness.h"

#include <algorithm>

namespace studio::runtime {

std::shared_ptr<Liveness::Beat> Liveness::attach(std::string name) {
  auto beat = std::make_shared<Beat>(std::move(name), SteadyClock::now());
  std::lock_guard lock(mutex_);
  beats_.push_back(beat);
  return beat;
}

void Liveness::detach(const std::shared_ptr<Beat>& beat) {
  std::lock_guard lock(mutex_);
  std::erase(beats_, beat);
}

std::optional<Liveness::Stall> Liveness::stalled(SteadyClock::time_point now) const {
  std::lock_guard lock(mutex_);
  std::optional<Stall> worst;
  for (const auto& beat : beats_) {
    const auto silent = now - beat->last();
    if (silent > bound_ && (!worst || silent > worst->silent)) worst = Stall{beat->name(), silent};
  }
  return worst;
}

}  // namespace studio::runtime

// A test fixture (not a studio service): the smallest node that exercises service_main end to
// end — config keys of its own, a counter, health — so runtime_service_test can check the
// lifecycle, notifications, status samples and config errors on a real process.
#include <atomic>
#include <thread>

#include "runtime/service.h"

namespace {

class ProbeNode : public studio::runtime::Node {
 public:
  ProbeNode(studio::runtime::Counter& ticks, bool degraded) : ticks_(ticks), degraded_(degraded) {}
  studio::Expected<void> start() override {
    running_ = true;
    worker_ = std::thread([this] {
      while (running_) {
        ticks_.add();
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
    return {};
  }
  void stop() override {
    running_ = false;
    if (worker_.joinable()) worker_.join();
  }
  studio::runtime::NodeHealth health() override {
    return {.degraded = degraded_, .frame = ticks_.value(), .capture_ns = 0, .input_hz = 0, .output_hz = 100};
  }
  ~ProbeNode() override { stop(); }

 private:
  studio::runtime::Counter& ticks_;
  bool degraded_;
  std::atomic<bool> running_{false};
  std::thread worker_;
};

}  // namespace

int main(int argc, char** argv) {
  studio::runtime::ServiceDefinition d;
  d.name = "probe";
  d.summary = "Runtime test fixture: ticks a counter at 100 Hz.";
  d.config_help = "  degraded: BOOL    report DEGRADED instead of RUNNING (default false)\n";
  d.create = [](studio::yaml::MapReader& config, studio::runtime::NodeContext& ctx)
      -> studio::Expected<std::unique_ptr<studio::runtime::Node>> {
    bool degraded = false;
    if (auto n = config.optional("degraded")) {
      auto v = n->as_bool();
      if (!v) return std::unexpected(v.error());
      degraded = *v;
    }
    return std::make_unique<ProbeNode>(ctx.metrics.counter("ticks"), degraded);
  };
  return studio::runtime::service_main(argc, argv, d);
}

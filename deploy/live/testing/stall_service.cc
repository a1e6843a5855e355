// Test-only service (not installed): service_main with a node that stalls on demand, so a test
// playing systemd can check that the watchdog pings stop (systemd then kills and restarts the
// service) and resume when the stall ends:
//   stall_file: PATH   (required) health() — called by the runtime's main loop, the loop that
//                      publishes studio/service/status and pings the watchdog — sleeps while
//                      PATH exists: a stalled main loop;
//   wedge_file: PATH   (optional) the node's ServiceLoop runs a 20 ms timer whose turn does not
//                      end while PATH exists: a wedged loop thread, the main loop still running
//                      (runtime/liveness.h: the pings stop after `loop_stall`).
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "runtime/service.h"
#include "runtime/service_loop.h"

namespace {

using namespace std::chrono_literals;

bool exists(const std::string& path) { return !path.empty() && ::access(path.c_str(), F_OK) == 0; }

class StallNode : public studio::runtime::Node {
 public:
  StallNode(studio::runtime::NodeContext& context, std::string stall, std::string wedge)
      : stall_(std::move(stall)), wedge_(std::move(wedge)), loop_(context, "stall") {
    loop_.every(20ms, [this](studio::runtime::SteadyClock::time_point) {
      loop_.counter("turns").add();
      while (exists(wedge_) && loop_.running()) std::this_thread::sleep_for(10ms);
    });
  }
  studio::Expected<void> start() override { return loop_.start(); }
  void stop() override { loop_.stop(); }
  studio::runtime::NodeHealth health() override {
    while (exists(stall_)) std::this_thread::sleep_for(10ms);
    return loop_.health();
  }

 private:
  std::string stall_, wedge_;
  studio::runtime::ServiceLoop loop_;  // last: stopped before the state it uses
};

}  // namespace

int main(int argc, char** argv) {
  studio::runtime::ServiceDefinition d;
  d.name = "stall";
  d.summary =
      "Test fixture: the main loop stalls while stall_file exists, the service loop's "
      "thread while wedge_file exists.";
  d.config_help =
      "  stall_file: PATH   health() (the main loop) blocks while PATH exists (required)\n"
      "  wedge_file: PATH   a service-loop timer's turn blocks while PATH exists (optional)\n";
  d.create = [](studio::yaml::MapReader& config, studio::runtime::NodeContext& context)
      -> studio::Expected<std::unique_ptr<studio::runtime::Node>> {
    auto stall = config.required("stall_file");
    if (!stall) return std::unexpected(stall.error());
    auto stall_path = stall->as_string();
    if (!stall_path) return std::unexpected(stall_path.error());
    std::string wedge_path;
    if (auto wedge = config.optional("wedge_file")) {
      auto path = wedge->as_string();
      if (!path) return std::unexpected(path.error());
      wedge_path = *path;
    }
    return std::make_unique<StallNode>(context, *stall_path, wedge_path);
  };
  return studio::runtime::service_main(argc, argv, d);
}

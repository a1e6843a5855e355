// Test-only service (not installed): service_main with a node whose health() blocks while a file
// exists, so a test can stall the runtime's main loop on demand — the loop that publishes
// studio/service/status and pings the systemd watchdog — and check that the pings stop (systemd
// then kills and restarts the service) and resume when the stall ends.
//   config: stall_file: PATH   (required; health() sleeps while PATH exists)
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "runtime/service.h"

namespace {

class StallNode : public studio::runtime::Node {
 public:
  explicit StallNode(std::string file) : file_(std::move(file)) {}
  studio::Expected<void> start() override { return {}; }
  void stop() override {}
  studio::runtime::NodeHealth health() override {
    while (::access(file_.c_str(), F_OK) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return {};
  }

 private:
  std::string file_;
};

}  // namespace

int main(int argc, char** argv) {
  studio::runtime::ServiceDefinition d;
  d.name = "stall";
  d.summary = "Test fixture: the main loop stalls while stall_file exists.";
  d.config_help = "  stall_file: PATH   health() blocks while PATH exists (required)\n";
  d.create = [](studio::yaml::MapReader& config, studio::runtime::NodeContext&)
      -> studio::Expected<std::unique_ptr<studio::runtime::Node>> {
    auto n = config.required("stall_file");
    if (!n) return std::unexpected(n.error());
    auto path = n->as_string();
    if (!path) return std::unexpected(path.error());
    return std::make_unique<StallNode>(*path);
  };
  return studio::runtime::service_main(argc, argv, d);
}

// studio-capture: the capture server (issue 3 item 7).
//   studio-capture --config capture.yaml     the node (runtime::service_main)
//   studio-capture verify-take DIR           check a recorded take and rebuild its index
#include <signal.h>

#include <cstring>

#include "capture_config.h"
#include "capture_node.h"
#include "runtime/service.h"
#include "verify_take.h"

int main(int argc, char** argv) {
  using namespace studio;
  if (argc >= 2 && std::strcmp(argv[1], "verify-take") == 0)
    return capture::node::verify_take_main(argc, argv);
  // A file size limit (ulimit -f) must end a take with EFBIG, not kill the server.
  ::signal(SIGXFSZ, SIG_IGN);
  runtime::ServiceDefinition d;
  d.name = "capture";
  d.summary =
      "Capture server: per camera publishes alpha masks, images and state, applies camera "
      "control and records takes on command. Also: studio-capture verify-take DIR.";
  d.config_help = capture::node::kConfigHelp;
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = capture::node::read_capture_config(config);
    if (!options) return std::unexpected(options.error());
    return std::make_unique<capture::node::CaptureNode>(std::move(*options), ctx);
  };
  return runtime::service_main(argc, argv, d);
}

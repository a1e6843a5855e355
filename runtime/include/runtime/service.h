#pragma once
// The service runtime every node binary shares (DESIGN §2 rule 4, issue 2 item 4).
//
//   int main(int argc, char** argv) {
//     return studio::runtime::service_main(argc, argv, hull::service_definition());
//   }
//
// service_main:
//   1. blocks SIGINT/SIGTERM into a signalfd before any thread exists;
//   2. parses `--config FILE` / `--help` (other subcommands are the binary's own, dispatched
//      before service_main);
//   3. reads the config strictly: the common keys below plus the service's own keys, one clear
//      line "file:line: field: problem" for an unknown, missing or malformed key;
//   4. creates the DDS participant, the node (configure), starts it, sends READY=1 to
//      $NOTIFY_SOCKET, then publishes studio/service/status every `status_period` and pings the
//      systemd watchdog (WATCHDOG=1) from the main loop, so a wedged main loop is restarted;
//      it pings only while every ServiceLoop of the node has come round within `loop_stall`
//      (runtime/liveness.h), so a wedged loop thread stops the pings too (systemd restarts the
//      service) and, meanwhile, the status says DEGRADED and STATUS= names the loop;
//   5. on SIGINT/SIGTERM: STOPPING=1, node->stop(), a last status with state STOPPING, exit 0.
//
// Common config keys (all optional):
//   instance: cam0          # instance name in ServiceStatus (default: host name)
//   domain: 0               # DDS domain id (default: $STUDIO_DDS_DOMAIN, else Cyclone's default)
//   dds_config: FILE        # Cyclone XML profile (default: $CYCLONEDDS_URI)
//   status_period: 1.0      # seconds between ServiceStatus samples (0.1 .. 60)
//   log: info               # log spec, e.g. "info,hull=debug" (default: $STUDIO_LOG or info)
//   loop_stall: 5           # seconds a ServiceLoop may take for one turn before the service
//                           # counts as stalled (0.05 .. 600; default: half of the watchdog
//                           # interval, $WATCHDOG_USEC / 2, when systemd asks for pings, else 10)

#include <functional>
#include <memory>
#include <string>

#include "core/error.h"
#include "runtime/liveness.h"
#include "runtime/metrics.h"
#include "wire/entity.h"
#include "yaml_io/node.h"

namespace studio::runtime {

// What a running node reports; filled by the node on each status period.
struct NodeHealth {
  bool degraded = false;  // running but not doing its full job (a camera missing, ...)
  uint64_t frame = 0;     // newest frame number handled
  int64_t capture_ns = 0; // capture time of that frame
  double input_hz = 0;
  double output_hz = 0;
};

// A service node built from a participant (so tests can host several nodes in one process).
class Node {
 public:
  virtual ~Node() = default;
  // Creates readers/writers/threads and starts working. An error here fails the service.
  virtual Expected<void> start() = 0;
  // Stops threads and releases DDS entities; idempotent.
  virtual void stop() = 0;
  virtual NodeHealth health() { return {}; }
};

struct NodeContext {
  const wire::Participant& participant;
  Metrics& metrics;  // counters and latency reported in ServiceStatus
  std::string instance;
  // service_main's: every ServiceLoop of the node stamps it each turn, and a loop that stops
  // turning stops the watchdog pings (runtime/liveness.h). nullptr: not monitored (tests).
  Liveness* liveness = nullptr;
};

struct ServiceDefinition {
  std::string name;         // "hull" (binary studio-hull, ServiceStatus.service)
  std::string summary;      // one line for --help
  std::string config_help;  // the service's own config keys, documented, for --help
  // Reads the service's own keys from `config` (the common keys are already consumed; the
  // runtime calls finish() afterwards, so unread keys are reported as unknown) and builds the
  // node. Must not start work yet.
  std::function<Expected<std::unique_ptr<Node>>(yaml::MapReader& config, NodeContext& context)> create;
};

struct CommonOptions {
  std::string instance;
  int64_t domain = -1;  // -1: default
  std::string dds_config;
  double status_period_s = 1.0;
  std::string log_spec;
  double loop_stall_s = 0;  // 0: the default (half the watchdog interval, else 10 s)
};

// Reads and consumes the common keys from `config`.
Expected<CommonOptions> read_common_options(yaml::MapReader& config);

int service_main(int argc, char** argv, const ServiceDefinition& definition);

}  // namespace studio::runtime

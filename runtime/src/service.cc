#include "runtime/service.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

#include "core/log.h"
#include "runtime/notify.h"
#include "runtime/signals.h"
#include "runtime/status_publisher.h"
#include "yaml_io/options.h"

namespace studio::runtime {
namespace {

constexpr std::string_view kCategory = "runtime";

void print_help(const ServiceDefinition& d) {
  std::printf(
      "usage: studio-%s --config FILE\n\n%s\n\n"
      "Runs as a DDS service until SIGINT/SIGTERM; speaks the systemd notify protocol\n"
      "(READY=1, WATCHDOG=1, STOPPING=1) when $NOTIFY_SOCKET is set.\n\n"
      "Common config keys (all optional):\n"
      "  instance: NAME         instance name in studio/service/status (default: host name)\n"
      "  domain: N              DDS domain id (default: $STUDIO_DDS_DOMAIN, else Cyclone's "
      "default)\n"
      "  dds_config: FILE       Cyclone DDS XML profile (default: $CYCLONEDDS_URI)\n"
      "  status_period: S       seconds between status samples, 0.1..60 (default 1)\n"
      "  log: SPEC              log levels, e.g. info,%s=debug (default: $STUDIO_LOG or info)\n"
      "  loop_stall: S          seconds one turn of the service loop may take before the\n"
      "                         service counts as stalled: no more WATCHDOG=1 (systemd restarts\n"
      "                         it), DEGRADED in its status, STATUS= names the loop; 0.05..600\n"
      "                         (default: half of $WATCHDOG_USEC when set, else 10)\n\n"
      "%s keys:\n%s",
      d.name.c_str(), d.summary.c_str(), d.name.c_str(), d.name.c_str(), d.config_help.c_str());
}

studio_ServiceState state_of(const NodeHealth& h) {
  return h.degraded ? studio_SERVICE_DEGRADED : studio_SERVICE_RUNNING;
}

}  // namespace

Expected<CommonOptions> read_common_options(yaml::MapReader& config) {
  static const yaml::Schema<CommonOptions> schema{
      yaml::field("instance", &CommonOptions::instance,
                  [](const yaml::Node& n) -> Expected<std::string> {
                    auto v = n.as_string();
                    if (v && (v->empty() || v->size() > 63))
                      return n.fail("expected a name of 1..63 characters");
                    return v;
                  }),
      yaml::field("domain", &CommonOptions::domain,
                  [](const yaml::Node& n) -> Expected<int64_t> {
                    auto v = n.as_int();
                    if (v && (*v < 0 || *v > 232))
                      return n.fail("expected a DDS domain id in 0..232");
                    return v;
                  }),
      yaml::field("dds_config", &CommonOptions::dds_config,
                  [](const yaml::Node& n) -> Expected<std::string> {
                    auto v = n.as_string();
                    if (!v) return v;
                    if (::access(v->c_str(), R_OK) != 0)
                      return n.fail("cannot read '" + *v + "': " + std::strerror(errno));
                    return "file://" + *v;
                  }),
      yaml::field("status_period", &CommonOptions::status_period_s,
                  yaml::number_in(0.1, 60, "seconds in 0.1..60")),
      yaml::field("loop_stall", &CommonOptions::loop_stall_s,
                  yaml::number_in(0.05, 600, "seconds in 0.05..600")),
      yaml::field("log", &CommonOptions::log_spec,
                  [](const yaml::Node& n) -> Expected<std::string> {
                    auto v = n.as_string();
                    if (v && !log::configure(*v))
                      return n.fail("malformed log spec '" + *v + "' (e.g. info,hull=debug)");
                    return v;
                  }),
  };
  return schema.read_fields(config);
}

int service_main(int argc, char** argv, const ServiceDefinition& definition) {
  // Before any thread exists (DDS creates threads): signals go to the signalfd only.
  SignalWatcher signals({SIGINT, SIGTERM});
  const std::string prog = "studio-" + definition.name;

  std::string config_path;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      print_help(definition);
      return 0;
    }
    if (a == "--config") {
      if (i + 1 == argc) {
        std::fprintf(stderr, "%s: --config needs a FILE (see --help)\n", prog.c_str());
        return 2;
      }
      config_path = argv[++i];
    } else if (a.starts_with("--config=")) {
      config_path = std::string(a.substr(9));
    } else {
      std::fprintf(stderr, "%s: unknown argument '%s' (see --help)\n", prog.c_str(), argv[i]);
      return 2;
    }
  }
  if (config_path.empty()) {
    std::fprintf(stderr, "%s: --config FILE is required (see --help)\n", prog.c_str());
    return 2;
  }

  auto fail = [&](const Error& e) {
    std::fprintf(stderr, "%s: %s\n", prog.c_str(), e.message.c_str());
    notify("STATUS=" + e.message);
    return 1;
  };

  auto doc = yaml::load_file(config_path);
  if (!doc) return fail(doc.error());
  auto reader = yaml::MapReader::from(*doc);
  if (!reader) return fail(reader.error());
  auto common = read_common_options(*reader);
  if (!common) return fail(common.error());
  if (common->instance.empty()) common->instance = host_name().substr(0, 63);

  auto participant = wire::Participant::create(
      common->domain >= 0 ? dds_domainid_t(common->domain) : wire::default_domain(),
      common->dds_config);
  if (!participant) return fail(participant.error());

  using namespace std::chrono;
  const std::optional<microseconds> watchdog = watchdog_interval();
  const auto stall_bound = duration_cast<SteadyClock::duration>(
      common->loop_stall_s > 0 ? duration<double>(common->loop_stall_s)
      : watchdog               ? duration<double>(*watchdog) / 2
                               : duration<double>(10.0));
  Liveness liveness(stall_bound);  // outlives the node, whose loops attach to it
  Metrics metrics;
  NodeContext context{*participant, metrics, common->instance, &liveness};
  auto node = definition.create(*reader, context);
  if (!node) return fail(node.error());
  if (auto done = reader->finish(); !done) return fail(done.error());

  auto status = StatusPublisher::create(*participant, definition.name, common->instance);
  if (!status) return fail(status.error());
  if (auto started = (*node)->start(); !started) {
    (void)status->publish(studio_SERVICE_FAILED, {}, metrics.snapshot());
    return fail(started.error());
  }

  notify("READY=1\nSTATUS=running");
  STUDIO_LOG(info, kCategory) << definition.name << " (" << common->instance << ") running, pid "
                              << ::getpid();

  const auto status_period = duration_cast<milliseconds>(duration<double>(common->status_period_s));
  auto period = status_period;
  if (watchdog) period = std::min(period, duration_cast<milliseconds>(*watchdog / 2));
  period =
      std::max(milliseconds(1), std::min(period, duration_cast<milliseconds>(stall_bound / 2)));
  auto next_status = steady_clock::now();
  bool was_stalled = false;
  int signo = 0;
  while (true) {
    const auto now = steady_clock::now();
    // A loop stuck in one turn: no ping (systemd restarts the service), DEGRADED, say which.
    const std::optional<Liveness::Stall> stall = liveness.stalled(now);
    if (stall && !was_stalled) {
      char what[160];
      std::snprintf(what, sizeof what, "loop '%s' stalled: no turn for %.2f s (loop_stall %.2f s)",
                    stall->name.c_str(), duration<double>(stall->silent).count(),
                    duration<double>(stall_bound).count());
      STUDIO_LOG(error, kCategory) << what << (watchdog ? "; watchdog pings stopped" : "");
      notify(std::string("STATUS=") + what);
    } else if (!stall && was_stalled) {
      STUDIO_LOG(info, kCategory) << "service loops turning again";
      notify("STATUS=running");
    }
    was_stalled = stall.has_value();
    if (now >= next_status) {
      NodeHealth health = (*node)->health();
      health.degraded = health.degraded || stall.has_value();
      if (auto r = status->publish(state_of(health), health, metrics.snapshot()); !r)
        STUDIO_LOG(warn, kCategory) << "status: " << r.error().message;
      next_status = now + status_period;
    }
    if (watchdog && !stall) notify("WATCHDOG=1");
    const auto wait =
        std::min(period, duration_cast<milliseconds>(next_status - steady_clock::now()));
    if (auto s = signals.wait(std::max(wait, milliseconds(1)))) {
      signo = *s;
      break;
    }
  }

  STUDIO_LOG(info, kCategory) << "signal " << signo << " (" << strsignal(signo) << "): stopping";
  notify("STOPPING=1");
  (*node)->stop();
  (void)status->publish(studio_SERVICE_STOPPING, (*node)->health(), metrics.snapshot());
  return 0;
}

}  // namespace studio::runtime

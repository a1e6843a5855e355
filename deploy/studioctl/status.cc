#include "studioctl/status.h"

#include <cstdio>
#include <map>
#include <thread>

#include "studioctl/cli.h"
#include "studioctl/status_watch.h"
#include "studioctl/topic_reader.h"
#include "wire/endpoint.h"

namespace studio::ctl {

const char kStatusHelp[] =
    "usage: studioctl status [--wait S] [--require LIST] [--json]\n"
    "       studioctl status --watch S [--json]\n"
    "\n"
    "Collects studio/service/status for --wait S seconds (default 2.5; services publish every\n"
    "second) and lists every service heard: service, instance, state, host, pid, input and output\n"
    "rate, mean latency, and how long ago its last status was sent.\n"
    "\n"
    "  --require LIST   comma-separated SERVICE or SERVICE:INSTANCE (e.g. "
    "hull,tracker,capture:cam0):\n"
    "                   exit 1 and name on stderr each one not heard, or heard only as FAILED or\n"
    "                   STOPPING (for monitoring).\n"
    "  --json           one JSON object per service per line: the ServiceStatus members (IDL "
    "names)\n"
    "                   plus last_seen_s.\n"
    "  --watch S        instead: one line per change for S seconds (0.1..86400): a service up,\n"
    "                   restarted (new pid; the gap without status between the two processes),\n"
    "                   gone (liveliness lost: killed or cut off, after the 3 s lease), back, or\n"
    "                   its state changed (running, degraded, ...); --json: one object per event\n"
    "                   {time_ns, event, service, instance, host, pid, old_pid, state, gap_s}.\n"
    "\n"
    "Common options: --domain N, --dds-config FILE (default $STUDIO_DDS_DOMAIN, "
    "$CYCLONEDDS_URI).\n";

namespace {

struct Seen {
  wire::Owned<studio_ServiceStatus> status;
  int64_t source_ns = 0;
};

const char* state_name(studio_ServiceState s) {
  switch (s) {
    case studio_SERVICE_STARTING:
      return "starting";
    case studio_SERVICE_RUNNING:
      return "running";
    case studio_SERVICE_DEGRADED:
      return "degraded";
    case studio_SERVICE_STOPPING:
      return "stopping";
    case studio_SERVICE_FAILED:
      return "failed";
  }
  return "?";
}

}  // namespace

int status_command(const std::vector<std::string>& argv) {
  auto a = parse_args(argv, {"--wait", "--require", "--watch"});
  if (!a) return complain("status", a.error().message, 2);
  if (a->help) {
    std::fputs(kStatusHelp, stdout);
    return 0;
  }
  if (!a->positional.empty())
    return complain("status", "unexpected argument '" + a->positional[0] + "'", 2);
  if (a->has("--watch")) {
    auto watch = seconds_flag(*a, "--watch", 0, 0.1, 86400);
    if (!watch) return complain("status", watch.error().message, 2);
    if (a->has("--require") || a->has("--wait"))
      return complain("status", "--watch does not take --require or --wait", 2);
    return status_watch(*a, *watch);
  }
  auto wait = seconds_flag(*a, "--wait", 2.5, 0.1, 600);
  if (!wait) return complain("status", wait.error().message, 2);
  std::vector<std::pair<std::string, std::string>> required;  // service, instance ("" = any)
  if (const auto* r = a->value("--require")) {
    std::size_t pos = 0;
    while (pos <= r->size()) {
      const std::size_t end = std::min(r->find(',', pos), r->size());
      const std::string item = r->substr(pos, end - pos);
      if (item.empty()) return complain("status", "--require: empty entry in '" + *r + "'", 2);
      const auto colon = item.find(':');
      required.emplace_back(item.substr(0, colon),
                            colon == std::string::npos ? "" : item.substr(colon + 1));
      pos = end + 1;
    }
  }

  auto p = open_participant(a->common);
  if (!p) return complain("status", p.error().message);
  auto topic = wire::Topic<studio_ServiceStatus>::create(*p);
  if (!topic) return complain("status", topic.error().message);
  auto reader = wire::Reader<studio_ServiceStatus>::create(*p, *topic);
  if (!reader) return complain("status", reader.error().message);

  std::map<std::pair<std::string, std::string>, Seen> seen;
  const auto deadline = std::chrono::steady_clock::now() + to_ns(*wait);
  while (true) {
    for (auto& s : reader->take(256)) {
      if (!s.meta.valid_data) continue;
      auto key = std::make_pair(std::string(wire::str(s.data->service)),
                                std::string(wire::str(s.data->instance)));
      auto& slot = seen[key];
      if (s.meta.source_timestamp >= slot.source_ns)
        slot = Seen{std::move(s.data), s.meta.source_timestamp};
    }
    if (std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }

  const int64_t now = realtime_ns();
  const IdlType* type = find_type(&studio_ServiceStatus_desc);
  if (!a->common.json)
    std::printf("%-12s %-16s %-9s %-16s %7s %8s %8s %9s %9s\n", "SERVICE", "INSTANCE", "STATE",
                "HOST", "PID", "IN_HZ", "OUT_HZ", "LAT_MS", "SEEN_S");
  for (const auto& [key, s] : seen) {
    const double age = double(now - s.source_ns) * 1e-9;
    if (a->common.json) {
      Printer pr(Printer::Mode::json);
      pr.begin_object();
      type->print(pr, s.status.get());
      pr.key("last_seen_s");
      pr.number(age);
      pr.end_object();
      emit(pr.take());
    } else {
      const auto& st = *s.status;
      std::printf("%-12s %-16s %-9s %-16s %7d %8.2f %8.2f %9.2f %9.1f\n", key.first.c_str(),
                  key.second.c_str(), state_name(st.state), std::string(wire::str(st.host)).c_str(),
                  st.pid, st.input_hz, st.output_hz, st.latency_ms, age);
    }
  }
  if (seen.empty() && !a->common.json)
    std::fprintf(stderr, "studioctl status: no service heard within %.1f s on this domain\n",
                 *wait);
  std::fflush(stdout);

  std::string missing;
  for (const auto& [service, instance] : required) {
    bool ok = false;
    for (const auto& [key, s] : seen)
      if (key.first == service && (instance.empty() || key.second == instance) &&
          s.status->state != studio_SERVICE_FAILED && s.status->state != studio_SERVICE_STOPPING)
        ok = true;
    if (!ok)
      missing += (missing.empty() ? "" : ", ") + service + (instance.empty() ? "" : ":" + instance);
  }
  if (!missing.empty()) return complain("status", "required but not running: " + missing);
  return 0;
}

}  // namespace studio::ctl

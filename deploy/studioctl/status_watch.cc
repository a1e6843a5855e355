#include "studioctl/status_watch.h"

#include <time.h>

#include <cinttypes>
#include <cstdio>
#include <map>
#include <thread>

#include "studioctl/cli.h"
#include "studioctl/printer.h"
#include "wire/endpoint.h"

namespace studio::ctl {
namespace {

struct Service {
  int32_t pid = 0;
  studio_ServiceState state = studio_SERVICE_STARTING;
  int64_t last_ns = 0;  // source time of its newest status
  bool alive = false;
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

std::string clock_text(int64_t ns) {
  const time_t t = time_t(ns / 1'000'000'000);
  tm utc{};
  gmtime_r(&t, &utc);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%02d:%02d:%02d.%03d", utc.tm_hour, utc.tm_min, utc.tm_sec,
                int(ns / 1'000'000 % 1000));
  return buf;
}

struct Event {
  const char* kind;  // up, restarted, state, gone, back
  std::string service, instance, host;
  int32_t pid = 0, old_pid = 0;
  studio_ServiceState state = studio_SERVICE_STARTING;
  double gap_s = -1;  // restarted / back / gone: seconds without a status
  int64_t at_ns = 0;
};

void print(const Event& e, bool json) {
  if (json) {
    Printer pr(Printer::Mode::json);
    pr.begin_object();
    pr.key("time_ns");
    pr.number(e.at_ns);
    pr.key("event");
    pr.string(e.kind);
    pr.key("service");
    pr.string(e.service);
    pr.key("instance");
    pr.string(e.instance);
    pr.key("host");
    pr.string(e.host);
    pr.key("pid");
    pr.number(int64_t(e.pid));
    pr.key("old_pid");
    pr.number(int64_t(e.old_pid));
    pr.key("state");
    pr.string(state_name(e.state));
    pr.key("gap_s");
    if (e.gap_s >= 0)
      pr.number(e.gap_s);
    else
      pr.null();
    pr.end_object();
    emit(pr.take());
    return;
  }
  const std::string who = e.service + ":" + e.instance;
  char buf[256];
  const std::string kind = e.kind;
  if (kind == "up")
    std::snprintf(buf, sizeof buf, "%s up on %s, pid %d, %s", who.c_str(), e.host.c_str(), e.pid,
                  state_name(e.state));
  else if (kind == "restarted")
    std::snprintf(buf, sizeof buf, "%s restarted: pid %d -> %d, no status for %.2f s", who.c_str(),
                  e.old_pid, e.pid, e.gap_s);
  else if (kind == "back")
    std::snprintf(buf, sizeof buf, "%s back, pid %d, after %.2f s without a status", who.c_str(),
                  e.pid, e.gap_s);
  else if (kind == "gone")
    std::snprintf(buf, sizeof buf,
                  "%s GONE: pid %d lost its liveliness (no status for %.2f s; killed or cut off)",
                  who.c_str(), e.pid, e.gap_s);
  else
    std::snprintf(buf, sizeof buf, "%s is %s", who.c_str(), state_name(e.state));
  emit(clock_text(e.at_ns) + " " + buf);
}

}  // namespace

int status_watch(const Args& a, double seconds) {
  auto p = open_participant(a.common);
  if (!p) return complain("status", p.error().message);
  auto topic = wire::Topic<studio_ServiceStatus>::create(*p);
  if (!topic) return complain("status", topic.error().message);
  auto reader = wire::Reader<studio_ServiceStatus>::create(*p, *topic);
  if (!reader) return complain("status", reader.error().message);

  std::map<std::pair<std::string, std::string>, Service> seen;
  const auto deadline = std::chrono::steady_clock::now() + to_ns(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    for (auto& s : reader->take(256)) {
      auto key = std::make_pair(std::string(wire::str(s.data->service)),
                                std::string(wire::str(s.data->instance)));
      Event e{"", key.first, key.second, std::string(wire::str(s.data->host))};
      e.at_ns = realtime_ns();
      auto [it, fresh] = seen.try_emplace(key);
      Service& svc = it->second;
      if (!s.meta.valid_data) {
        // No writer left (liveliness lease expired after a kill -9, or the host is cut off), or
        // the service unregistered on a clean stop.
        if (!s.meta.alive && svc.alive) {
          svc.alive = false;
          e.kind = "gone";
          e.pid = svc.pid;
          e.state = svc.state;
          e.gap_s = double(e.at_ns - svc.last_ns) * 1e-9;
          print(e, a.common.json);
        }
        continue;
      }
      const auto& st = *s.data;
      e.pid = st.pid;
      e.state = st.state;
      if (fresh) {
        e.kind = "up";
      } else if (st.pid != svc.pid && s.meta.source_timestamp >= svc.last_ns) {
        e.kind = "restarted";
        e.old_pid = svc.pid;
        e.gap_s = double(s.meta.source_timestamp - svc.last_ns) * 1e-9;
      } else if (!svc.alive) {
        e.kind = "back";
        e.gap_s = double(s.meta.source_timestamp - svc.last_ns) * 1e-9;
      } else if (st.state != svc.state) {
        e.kind = "state";
      }
      if (st.pid != svc.pid && !fresh && s.meta.source_timestamp < svc.last_ns) continue;  // old
      svc.pid = st.pid;
      svc.state = st.state;
      svc.last_ns = s.meta.source_timestamp;
      svc.alive = true;
      if (*e.kind) print(e, a.common.json);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

}  // namespace studio::ctl

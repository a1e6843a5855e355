#include "runtime/status_publisher.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "wire/sample.h"

namespace studio::runtime {

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

Expected<StatusPublisher> StatusPublisher::create(const wire::Participant& participant, std::string service,
                                                  std::string instance) {
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant);
  if (!topic) return std::unexpected(topic.error());
  auto writer = wire::Writer<studio_ServiceStatus>::create(participant, *topic);
  if (!writer) return std::unexpected(writer.error());
  return StatusPublisher(std::move(*topic), std::move(*writer), std::move(service), std::move(instance),
                         host_name());
}

namespace {
// Bounded IDL strings: clip rather than fail (a status must always go out).
template <std::size_t N>
void set_clipped(char (&dst)[N], const std::string& value) {
  wire::set(dst, std::string_view(value).substr(0, N - 1));
}
}  // namespace

Expected<void> StatusPublisher::publish(studio_ServiceState state, const NodeHealth& health,
                                        const MetricsSnapshot& metrics) {
  wire::Owned<studio_ServiceStatus> s;
  set_clipped(s->service, service_);
  set_clipped(s->instance, instance_);
  set_clipped(s->host, host_);
  s->pid = int32_t(::getpid());
  s->state = state;
  s->frame = health.frame;
  s->capture_ns = health.capture_ns;
  s->input_hz = health.input_hz;
  s->output_hz = health.output_hz;
  s->latency_ms = metrics.latency_mean_ms;
  std::vector<studio_Counter> counters;
  // Totals as they are, rates as "<name>_hz"; the IDL bounds the list at 64.
  // A gauge that is not finite (an unbounded allowance, a ratio before its first sample) is left
  // out: the readers validate every value, and one would refuse the whole status.
  auto add = [&](const std::string& name, double value) {
    if (counters.size() >= 64 || !std::isfinite(value)) return;
    studio_Counter c{};
    set_clipped(c.name, name);
    c.value = value;
    counters.push_back(c);
  };
  for (const auto& c : metrics.counters) add(c.name, c.value);
  for (const auto& r : metrics.rates) add(r.name + "_hz", r.value);
  wire::assign(s->counters, counters);
  return writer_.write(*s);
}

}  // namespace studio::runtime

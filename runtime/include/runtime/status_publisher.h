#pragma once
// Publishes studio/service/status (ServiceStatus, keyed by service + instance) with the state,
// host, pid, rates, latency and counters of one service. The topic's QoS (best-effort with a
// liveliness lease, from the wire table) lets studioctl and the preview see a dead service go
// away when its lease expires.

#include <string>

#include "runtime/metrics.h"
#include "runtime/service.h"
#include "wire/endpoint.h"

namespace studio::runtime {

class StatusPublisher {
 public:
  static Expected<StatusPublisher> create(const wire::Participant& participant, std::string service,
                                          std::string instance);
  // state: one of studio_ServiceState.
  Expected<void> publish(studio_ServiceState state, const NodeHealth& health, const MetricsSnapshot& metrics);
  const std::string& host() const { return host_; }

 private:
  StatusPublisher(wire::Topic<studio_ServiceStatus> topic, wire::Writer<studio_ServiceStatus> writer,
                  std::string service, std::string instance, std::string host)
      : topic_(std::move(topic)), writer_(std::move(writer)), service_(std::move(service)),
        instance_(std::move(instance)), host_(std::move(host)) {}
  wire::Topic<studio_ServiceStatus> topic_;
  wire::Writer<studio_ServiceStatus> writer_;
  std::string service_, instance_, host_;
};

std::string host_name();

}  // namespace studio::runtime

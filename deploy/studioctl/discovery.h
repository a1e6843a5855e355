#pragma once
// What the domain holds, from Cyclone's built-in discovery readers (DCPSParticipant,
// DCPSPublication, DCPSSubscription): every writer and reader of other participants, with the
// host, pid and process name their participant announces (Cyclone's __Hostname, __Pid and
// __ProcessName properties) and the reliability and durability they were created with (history
// is not part of discovery).

#include <dds/dds.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "wire/entity.h"

namespace studio::ctl {

struct Endpoint {
  bool writer = false;
  std::string topic;
  std::string type;  // e.g. "studio::AlphaMask"
  std::string host;  // "" when the participant did not say
  int pid = 0;
  std::string process;
  std::string reliability;  // "reliable" | "best-effort"
  std::string durability;   // "volatile" | "transient-local" | ...
};

// Endpoints of every participant but `self`, after `wait` for discovery.
Expected<std::vector<Endpoint>> discover(const wire::Participant& self,
                                         std::chrono::nanoseconds wait);

}  // namespace studio::ctl

#pragma once
// The systemd notification protocol, spoken directly (no libsystemd): a datagram with
// newline-separated assignments ("READY=1", "WATCHDOG=1", "STOPPING=1", "STATUS=...") sent to
// the AF_UNIX socket named by $NOTIFY_SOCKET ('@' prefix = abstract namespace). Under systemd
// (Type=notify, WatchdogSec=) this drives the unit's state; the test harness owns a socket of
// its own to learn when a service is ready.

#include <chrono>
#include <optional>
#include <string_view>

namespace studio::runtime {

// Sends `state` to $NOTIFY_SOCKET without blocking. Returns false when the variable is unset or
// the send fails, e.g. because the receiver's queue is full (a service keeps running either way).
bool notify(std::string_view state);

// The watchdog interval requested by the service manager ($WATCHDOG_USEC, honouring
// $WATCHDOG_PID), or nullopt. Send "WATCHDOG=1" at least every half of it.
std::optional<std::chrono::microseconds> watchdog_interval();

}  // namespace studio::runtime

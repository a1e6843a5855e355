#pragma once
// For the GigE Vision tests that ctest runs inside a private network namespace
// (capture/run_in_netns.sh): whether this process is in one.
#include <net/if.h>

#include <string>

namespace studio::capture {

// True when loopback is the only network interface: we are in a private namespace.
inline bool only_loopback() {
  struct if_nameindex* list = if_nameindex();
  if (!list) return false;
  bool only_lo = true;
  for (struct if_nameindex* i = list; i->if_index != 0; ++i)
    only_lo &= std::string(i->if_name) == "lo";
  if_freenameindex(list);
  return only_lo;
}

}  // namespace studio::capture

#pragma once
// studioctl status --watch S: one line per change of the studio's services for S seconds (an
// operator's tail of studio/service/status): up, restarted (a new pid for the same service and
// instance, with the gap between the old process's last status and the new one's first), gone
// (liveliness lost: killed or cut off), back, and state changes (running, degraded, ...).

#include "studioctl/cli.h"

namespace studio::ctl {

int status_watch(const Args& a, double seconds);

}  // namespace studio::ctl

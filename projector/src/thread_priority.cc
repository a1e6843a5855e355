#include "projector/thread_priority.h"

#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace studio::projector {

std::string lower_this_thread(int nice_increment, bool keep_realtime) {
  const int policy = ::sched_getscheduler(0);
  if (policy == SCHED_FIFO || policy == SCHED_RR) {
    sched_param p{};
    p.sched_priority = keep_realtime ? 1 : 0;
    if (::sched_setscheduler(0, keep_realtime ? policy : SCHED_OTHER, &p) != 0)
      return std::string("sched_setscheduler: ") + std::strerror(errno);
    if (keep_realtime) return {};
  }
  if (nice_increment <= 0) return {};
  // PRIO_PROCESS with this thread's id sets this thread's nice value alone.
  const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
  errno = 0;
  const int current = ::getpriority(PRIO_PROCESS, tid);
  if (errno != 0) return std::string("getpriority: ") + std::strerror(errno);
  if (::setpriority(PRIO_PROCESS, tid, std::min(19, current + nice_increment)) != 0)
    return std::string("setpriority: ") + std::strerror(errno);
  return {};
}

}  // namespace studio::projector

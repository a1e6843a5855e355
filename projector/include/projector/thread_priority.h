#pragma once
// Lowering the calling thread's own priority below its process's (Linux: the scheduling policy
// and the nice value are per thread; lowering one's own needs no capability). Used by the
// projector's helper threads — the motion fit (fit_worker.h) and the scene thread — so that the
// render thread and its rasteriser keep the CPU they need.

#include <string>

namespace studio::projector {

// A time-sharing caller: its nice value + `nice_increment` (at most 19). A real-time caller
// (SCHED_FIFO/RR): `keep_realtime`, the lowest real-time priority (1) of its policy; otherwise
// time-sharing, then the nice increment as above. Empty when done, else why not in a few words
// ("setpriority: Operation not permitted"); the thread then keeps what it had.
std::string lower_this_thread(int nice_increment, bool keep_realtime = false);

}  // namespace studio::projector

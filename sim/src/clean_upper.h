#pragma once
// The simulator is built for x86-64-v2: its double-precision arithmetic is legacy (non-VEX) SSE.
// When a caller leaves the upper halves of the YMM registers dirty (256-bit AVX code that returns
// without `vzeroupper`), every such SSE instruction afterwards pays for the merge with the dirty
// upper state until something clears it; measured on this machine (AMD EPYC, KVM) a render then
// costs 1.8x its CPU time (capture_server_bench with and without the in-process keyer between
// renders: 4.3-4.9 vs 2.5 ms per camera frame, issue 20). The entry points that do the per-frame
// work (SimulatedStudio::render, render_all) clear the state first: one `vzeroupper` (no effect
// on any value the renderer reads), skipped on CPUs without AVX.

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace studio::sim::detail {

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx"))) inline void vzeroupper_avx() { _mm256_zeroupper(); }
inline void clean_avx_upper_state() {
  static const bool avx = __builtin_cpu_supports("avx");
  if (avx) vzeroupper_avx();
}
#else
inline void clean_avx_upper_state() {}
#endif

}  // namespace studio::sim::detail

#pragma once
// Test aid: the processor's own record of whether the upper halves of the YMM/ZMM registers are
// in use (XGETBV with ECX = 1, XINUSE: bit 2 = the upper halves of YMM0-15, bit 6 = those of
// ZMM0-15). Code that leaves them dirty (256-bit AVX returning without vzeroupper) makes every
// legacy-SSE instruction after it pay a merge penalty (1.8x the simulator's render time on this
// machine, issue 20); tests check the state directly instead of timing anything.
#include <cstdint>

#if defined(__x86_64__)
#include <cpuid.h>
#endif

namespace studio::testing {

#if defined(__x86_64__)
inline constexpr uint64_t kAvxUpperState = (1u << 2) | (1u << 6);

// Whether the CPU has AVX, the OS enabled it, and XGETBV(1) exists.
inline bool xinuse_readable() {
  unsigned a, b, c, d;
  if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & bit_OSXSAVE) || !(c & bit_AVX)) return false;
  if (!__get_cpuid_count(0xD, 1, &a, &b, &c, &d)) return false;
  return (a & (1u << 2)) != 0;
}

__attribute__((noinline)) inline uint64_t xinuse() {
  uint32_t lo, hi;
  asm volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(1));
  return (uint64_t(hi) << 32) | lo;
}

// Leaves the YMM upper halves dirty, as a 256-bit routine returning without vzeroupper does.
__attribute__((noinline)) inline void dirty_avx_upper() {
  asm volatile("vpcmpeqd %%ymm15, %%ymm15, %%ymm15" ::: "xmm15");
}

// Clears them (vzeroupper), for a clean start.
__attribute__((noinline)) inline void clean_avx_upper() { asm volatile("vzeroupper" ::: "memory"); }
#endif

}  // namespace studio::testing

#pragma once
// Row kernels of the keyer (private): a row of 3-byte pixels -> one bit per pixel (bit x of word
// x/64 set = pixel x is foreground; bits past the width are zero), and bits -> runs.
// Variants: scalar (any CPU), SSSE3 (16 pixels per step), AVX2 (32 pixels per step), picked once
// at run time from the CPU's features.

#include <cstdint>

#include "core/run_mask.h"

namespace studio::keyer::detail {

struct ChromaParams {
  int k = 2, o1 = 0, o2 = 1;  // byte offsets in a pixel of the key channel and the other two
  uint8_t max_excess = 0;     // foreground iff max(0, K - max(O1, O2)) <= max_excess
  // pshufb masks gathering plane p (0 = key, 1 = o1, 2 = o2) from 16-byte chunk c of 48 bytes.
  alignas(16) uint8_t shuffle[3][3][16] = {};
};
ChromaParams make_chroma_params(int k, int o1, int o2, uint8_t max_excess);

using ChromaRowFn = void (*)(const uint8_t* px, int width, const ChromaParams& p, uint64_t* bits);
// Foreground iff max over the 3 bytes of |px - plate| >= min_diff.
using DiffRowFn = void (*)(const uint8_t* px, const uint8_t* plate, int width, uint8_t min_diff,
                           uint64_t* bits);

struct Kernels {
  ChromaRowFn chroma;
  DiffRowFn diff;
  const char* name;
};
const Kernels& best_kernels();
const Kernels& scalar_kernels();

// Appends the runs of one row of bits to `out` (row y, which must be >= its last row).
void bits_to_runs(const uint64_t* bits, int width, int y, RunMask& out);

}  // namespace studio::keyer::detail

#pragma once
// Mask clean-up on runs (no image): remove foreground specks and fill small holes, at a cost
// linear in the number of runs (union-find over runs, each run compared with the overlapping runs
// of the row above). Foreground is 8-connected, background 4-connected (the dual pair, so a
// diagonal chain of actor pixels closes a hole).
//
//   1. foreground components with fewer than options.min_component_area pixels are removed;
//   2. background components that touch no image border and have at most
//      options.max_hole_area pixels are filled.

#include <cstdint>
#include <vector>

#include "core/run_mask.h"
#include "keyer/keyer_options.h"

namespace studio::keyer {

struct CleanupScratch {
  std::vector<uint32_t> parent;
  std::vector<uint64_t> area;
  std::vector<uint8_t> flags;
  RunMask kept;
  RunMask gaps;
};

struct CleanupStats {
  int components_removed = 0;
  int holes_filled = 0;
};

// `out` may not alias `in`. Scratch is reused between calls.
CleanupStats clean_mask(const RunMask& in, const CleanupOptions& options, RunMask& out,
                        CleanupScratch& scratch);

}  // namespace studio::keyer

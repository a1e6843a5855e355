#pragma once
// Mask clean-up on runs (no image): remove foreground specks and fill small holes, at a cost
// linear in the number of runs (union-find over runs, each run compared with the overlapping runs
// of the row above). Foreground is 8-connected, background 4-connected (the dual pair, so a
// diagonal chain of actor pixels closes a hole).
//
//   1. foreground components with fewer than options.min_component_area pixels are removed;
//   2. background components that touch no image border and have at most
//      options.max_hole_area pixels are filled, unless `shows_backing` (when given) returns true
//      for one of their runs: then the hole shows the clean backing and is a real gap. It is
//      called only for runs of holes that would otherwise be filled, so its cost is bounded by
//      the area of those holes.

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
  int gaps_kept = 0;  // holes small enough to fill but left open: they show the clean backing
};

// `out` may not alias `in`. Scratch is reused between calls.
CleanupStats clean_mask(const RunMask& in, const CleanupOptions& options, RunMask& out,
                        CleanupScratch& scratch);

// Does background run [begin, end) of row y show the clean backing? `context` is passed through.
using ShowsBackingFn = bool (*)(const void* context, int y, int32_t begin, int32_t end);
CleanupStats clean_mask(const RunMask& in, const CleanupOptions& options, RunMask& out,
                        CleanupScratch& scratch, ShowsBackingFn shows_backing, const void* context);

}  // namespace studio::keyer

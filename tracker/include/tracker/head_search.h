#pragma once
// The head finder: the two-box 3-D template filter of TCSVT 2004 §IV-D (eq. 9-12), evaluated
// exactly over the whole volume and extended to several actors.
//
// For a template position P (the min corner of V2, in voxels), with V2 the head-sized inner box
// and V1 ⊇ V2 the outer box, both positioned by P:
//   a2(P) = occupancy inside V2(P),  a1(P) = occupancy inside V1(P)           (eq. 9, 10)
//   M(P)  = 2·a2(P) − a1(P)  =  a2(P) − (occupancy of the ring V1 \ V2)         (eq. 11)
//   head  = argmax_P M(P)                                                       (eq. 12)
// A head is a full head-sized box with empty space around it. With exclude_below, V1 loses the
// part under V2 (neck and shoulders), so the body carrying the head does not count against it.
//
// Search. Box counts come from an IntegralVolume (O(1) each). The maximum over every P of the
// grid at full resolution is found exactly by best-first branch and bound over blocks of
// positions: for a block B, max_{P∈B} M(P) ≤ min(U2, 2·U2 − I1) with U2 the occupancy of the
// union of the V2(P) and I1 that of the intersection of the V1(P), P ∈ B (both boxes, O(1)).
// Leaves pop in decreasing M (ties: smallest (x, z, y) position first), which yields greedy
// non-maximum suppression for free: a leaf (or a whole block) whose V2 centre lies within
// suppression_radius (horizontally, any height: one head per actor) of an accepted head is
// dropped. find_exhaustive() computes M at every P and applies the same rule: the reference
// that find() must equal, and the benchmark's baseline.
//
// Head centre. The best V2 has its top at the top of the head; the reported position is the
// occupancy centroid of that box, then (refine_radius > 0) mean-shifted with a ball kernel of
// that radius clipped to the box, which drops most of the neck under the head.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "tracker/integral_volume.h"
#include "tracker/occupancy.h"

namespace studio::tracker {

struct HeadSearchOptions {
  // V2, the inner head-sized box (x, y, z) in metres, and V1, the outer box, which must contain
  // it; both are rounded to whole voxels of the grid searched (V2 at least one voxel).
  // V1 is centred on V2; exclude_below then cuts it at V2's bottom, so V1 reaches
  // (outer_box - head_box) / 2 beside and above V2. Defaults: an adult head seen by a visual hull
  // (a little larger than the skull) and a ring that catches shoulders beside and an arm above.
  Eigen::Vector3d head_box{0.22, 0.24, 0.22};
  Eigen::Vector3d outer_box{0.40, 0.64, 0.40};
  // Leave the part of V1 below V2 (neck, shoulders) out of the outer box.
  bool exclude_below = true;
  // Reference head: a ball of this diameter alone in the world scores confidence 1 (its M is
  // its volume); confidence = clamp(M / that, 0, 1).
  double head_diameter = 0.20;
  // Heads below this confidence are not reported.
  double min_confidence = 0.3;
  // One head per actor: no two heads closer than this horizontally (metres).
  double suppression_radius = 0.45;
  int max_heads = 4;
  // Ball kernel radius (metres) for the sub-voxel centre; 0 keeps the V2 centroid.
  double refine_radius = 0.11;
  int refine_iterations = 6;

  Expected<void> validate() const;
};

struct HeadDetection {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // head centre estimate, studio frame
  double score = 0;                                    // M of the best V2, in m³ of occupancy
  double confidence = 0;  // score relative to the reference head, in [0, 1]
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();  // the best V2, studio frame
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
};

struct HeadSearchStats {
  int64_t bounds = 0;       // block bounds (branch and bound) or positions (exhaustive) scored
  int64_t grid_voxels = 0;  // voxels of the grid searched
};

class HeadSearch {
 public:
  static Expected<HeadSearch> create(const HeadSearchOptions& options);

  // Heads in decreasing score, at most max_heads, each with confidence >= min_confidence.
  std::vector<HeadDetection> find(const OccupancyGrid& grid);
  // Same result by scoring every position (reference and benchmark baseline).
  std::vector<HeadDetection> find_exhaustive(const OccupancyGrid& grid);

  // M at V2 min corner p (voxels) for the grid of the last find*(), in 1/255 voxel units.
  int64_t score_at(const Eigen::Vector3i& p) const;
  const HeadSearchStats& stats() const { return stats_; }
  const HeadSearchOptions& options() const { return options_; }

 private:
  struct Block {
    int64_t bound;
    Eigen::Vector3i lo, hi;  // inclusive range of V2 min corners
  };
  explicit HeadSearch(const HeadSearchOptions& options) : options_(options) {}
  // Box sizes in voxels for this grid, integral volume; false if nothing is occupied.
  bool prepare(const OccupancyGrid& grid);
  int64_t bound(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) const;
  HeadDetection make_detection(const OccupancyGrid& grid, const Eigen::Vector3i& p,
                               int64_t score) const;
  // Largest horizontal distance (metres) from an accepted head's V2 centre to the V2 centres
  // of positions in [lo, hi], and the smallest; used for suppression.
  bool suppressed(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, bool whole) const;

  HeadSearchOptions options_;
  IntegralVolume integral_;
  Eigen::Vector3d voxel_ = Eigen::Vector3d::Ones();
  Eigen::Vector3i s2_ = Eigen::Vector3i::Ones();    // V2 size
  Eigen::Vector3i m_lo_ = Eigen::Vector3i::Zero();  // V1 margin below V2 (per axis)
  Eigen::Vector3i m_hi_ = Eigen::Vector3i::Zero();  // V1 margin above V2
  int64_t threshold_ = 1;                           // min score in count units
  double reference_ = 1;                            // reference score in count units
  std::vector<Block> heap_;
  std::vector<Eigen::Vector3i> accepted_;
  HeadSearchStats stats_;
};

}  // namespace studio::tracker

#pragma once
// What a camera sees (private to studio_hull): the visibility policy's "camera c sees point x"
// (hull/visibility.h) and the clipping helpers the cut paths share.
//
// A camera sees x when x is in front of it (w > 0) and projects into its image rectangle
// [-0.5, W-0.5] x [-0.5, H-0.5] (pixel-square edges). For a camera with lens distortion the test
// uses the ideal-pixel bounding box of the observed image border: a superset of the observed
// image, so a distorted camera may count as seeing a sliver just beyond its border (the safe
// direction: it only makes min_views easier to reach, never cuts more). Every test is a
// half-space in the homogeneous image point, so along a line x(t) = o + t d (image A + t B) the
// seen part is ONE interval of t: the frustum is convex.

#include <Eigen/Core>
#include <algorithm>
#include <span>
#include <vector>

#include "core/camera.h"
#include "hull/silhouette_cut.h"

namespace studio::hull::detail {

using Range = CutScratch::Piece;

// Restricts [lo, hi] to the t where alpha + t beta >= 0.
inline void clip_halfline(double alpha, double beta, double& lo, double& hi) {
  if (beta > 0) {
    lo = std::max(lo, -alpha / beta);
  } else if (beta < 0) {
    hi = std::min(hi, -alpha / beta);
  } else if (alpha < 0) {
    lo = 1, hi = 0;
  }
}

struct Rect {
  double u0, u1, v0, v1;
};

// The t-range of [lo, hi] where the homogeneous image point A + t B is in front of the camera
// (w > 0) and inside the rectangle. Empty when lo >= hi.
inline Range in_rect(const Eigen::Vector3d& A, const Eigen::Vector3d& B, const Rect& r, double lo,
                     double hi) {
  clip_halfline(A[2] - 1e-12, B[2], lo, hi);
  clip_halfline(A[0] - r.u0 * A[2], B[0] - r.u0 * B[2], lo, hi);
  clip_halfline(r.u1 * A[2] - A[0], r.u1 * B[2] - B[0], lo, hi);
  clip_halfline(A[1] - r.v0 * A[2], B[1] - r.v0 * B[2], lo, hi);
  clip_halfline(r.v1 * A[2] - A[1], r.v1 * B[2] - B[1], lo, hi);
  return {lo, hi};
}

// Ideal-pixel bounding box of the observed image border of a distorted camera.
Rect ideal_border_box(const Camera& camera);

// One camera's seeing region.
struct Frustum {
  Eigen::Matrix<double, 3, 4> P;  // K [R | t] (distortion-free part)
  Rect rect;                      // image rectangle in ideal pixels

  static Frustum of(const Camera& camera);
  // The part of [lo, hi] of the line o + t d that the camera sees (empty: lo >= hi).
  Range seen(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double lo, double hi) const {
    const Eigen::Vector3d A = P.leftCols<3>() * o + P.col(3), B = P.leftCols<3>() * d;
    return in_rect(A, B, rect, lo, hi);
  }
};

// Appends to *out the sorted, disjoint pieces of [lo, hi] covered by at least `need` of the
// (possibly empty) ranges; need <= 0 gives [lo, hi] itself. `events` is working memory.
void at_least(std::span<const Range> ranges, int need, double lo, double hi,
              std::vector<std::pair<double, int>>* events, std::vector<Range>* out);

// out = a ∩ b for sorted, disjoint float intervals `a` and pieces `b`; touching pieces merge.
void intersect(std::span<const Interval> a, std::span<const Range> b, std::vector<Interval>* out);

}  // namespace studio::hull::detail

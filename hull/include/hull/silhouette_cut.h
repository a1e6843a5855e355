#pragma once
// The silhouette cut (TCSVT 2004 §IV-B, Fig. 9): every line segment is projected into a camera
// image, intersected with the silhouette and the surviving pieces are re-projected onto the line.
//
// Geometry. A line x(t) = o + t d projects (distortion-free part, P = K [R | t]) to the
// homogeneous image point A + t B with A = P (o, 1), B = P (d, 0). Image intersections map back
// to t exactly by line-line intersection: v(t) = y  <=>  t = (y A2 - A1) / (B1 - y B2).
// The silhouette is the RunMask: pixel (x, y) covers [x-0.5, x+0.5) x [y-0.5, y+0.5).
//
// Two paths give the same hull to within half a pixel:
// - Pencil (fast, used when the camera has no lens distortion and every line of the set passes
//   through one common point X whose image V is outside the image with all pencil lines steeper
//   than 45° — the studio case: vertical columns, X at infinity along y, V the vanishing point):
//   the image-based visual hull idea. Once per mask, the lines through V are binned by where
//   they cross a reference row (bins of half a pixel) and the runs are swept row by row into,
//   per bin, the v-ranges where the bin's centre line is inside the silhouette; the sweep only
//   touches bins where the silhouette boundary changes, so it costs the boundary length, not the
//   area. Cutting one line then costs its bin's run count plus its interval count.
// - Row walker (exact for pixel squares, general): walks the rows crossed by each surviving
//   interval and intersects with that row's runs (binary search). Lens distortion: the line's
//   observed image curve is cut into chords of <= 8 px, each walked as a straight piece.
// Parts of a line a camera does not see (outside its image or behind it) are not judged by that
// camera's silhouette; the visibility policy below decides them.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/run_mask.h"
#include "hull/segment_set.h"

namespace studio::hull {

// The visibility policy (issue 18; docs/hull.md "Visibility policy"). A camera SEES a point when
// the point is in front of it and projects into its image (hull/src/frustum.h). A point is actor
// iff
//   (a) it lies inside the silhouette of EVERY camera that sees it, and
//   (b) at least `min_views` cameras see it.
// (a) alone (min_views 0, the former `outside: keep`) keeps every part of the box no camera sees,
// and a part seen by one camera is only bounded by that camera's silhouette cone: on a real rig
// with a loose box these come out as slabs and cones many times the actor's volume. Requiring
// every camera (min_views = kAllViews, the former `outside: cut`) cuts the actor wherever one
// camera's image ends before the actor does (feet at the edge of the acting area). Two views
// are the fewest that bound a point in depth (two cones from different centres cross in a
// bounded region around the actor), and the studio sees every point of its acting area with at
// least 2 cameras by design, so kDefaultMinViews = 2: the hull stays a superset of the actor
// wherever the actor stands in the acting area (the projector mask is drawn from it) and the
// unseen slabs are gone. The offline CLI and the node both default to it; a consumer that needs
// another policy sets its own min_views.
inline constexpr int kDefaultMinViews = 2;
inline constexpr int kAllViews = -1;  // min_views: every view given must see the point

struct CutOptions {
  int min_views = kDefaultMinViews;  // 0..64 or kAllViews
  int threads = 1;                   // columns are independent; 1..64
  bool allow_pencil = true;          // false forces the exact row walker (tests compare both)
  Expected<void> validate() const;
  // min_views for a cut with `views` views (kAllViews -> views).
  int required_views(std::size_t views) const {
    return min_views == kAllViews ? int(views) : min_views;
  }
};

// Reusable working memory for PreparedView::cut_line (one per thread).
struct CutScratch {
  struct Piece {
    double lo, hi;
  };
  std::vector<Piece> keep, result;
};

// A camera and its silhouette, prepared for cutting a family of lines through a common
// homogeneous point `pencil_point` (for grid columns: (e_axis, 0); for rays of a viewpoint:
// (centre, 1)). Preparing costs the mask's boundary length; cutting is thread-safe.
class PreparedView {
 public:
  // Fails when the mask size differs from the camera's. `domain`, when given, is a box holding
  // every interval that will be cut; if it projects entirely inside the image (in front of the
  // camera) the per-line in-image test is skipped.
  static Expected<PreparedView> create(const Camera& camera, const RunMask& mask,
                                       const Eigen::Vector4d& pencil_point,
                                       const CutOptions& options,
                                       const Eigen::AlignedBox3d* domain = nullptr);
  PreparedView(PreparedView&&) noexcept;
  PreparedView& operator=(PreparedView&&) noexcept;
  ~PreparedView();

  bool uses_pencil() const;
  bool domain_inside_image() const;
  // The part [lo', hi'] of [lo, hi] of the line o + t d that this camera sees (lo' >= hi': none).
  std::pair<double, double> seen(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double lo,
                                 double hi) const;
  // Cuts the sorted intervals `in` of the line o + t d by this camera alone: appends the parts
  // inside its silhouette and the parts it does not see (sorted, disjoint) to *out. The policy's
  // min_views is applied by the callers (cut(), viewpoint_cut()). `scratch` is reused between
  // calls (one per thread).
  void cut_line(const Eigen::Vector3d& o, const Eigen::Vector3d& d, std::span<const Interval> in,
                std::vector<Interval>* out, CutScratch* scratch) const;
  // Cheap early out, exact with respect to cut_line: true when cutting intervals spanning
  // [lo, hi] of the line would certainly leave nothing (pencil path, domain inside the image, and
  // the line's pencil bin holds no silhouette). False means "cut to find out".
  bool misses(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double lo, double hi) const;

 private:
  PreparedView();
  friend struct GridCutAccess;  // the grid fast path of cut() reads the pencil bins
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct View {
  const Camera* camera;
  const RunMask* mask;
};

// Cuts the segment set by every view's silhouette under the visibility policy (options.min_views
// counts the views of this call). Fails, leaving `set` untouched, on a mask whose size differs
// from its camera.
Expected<void> cut(SegmentSet& set, std::span<const View> views, const CutOptions& options = {});

// The hull from scratch: SegmentSet::full(grid) cut by every view.
Expected<SegmentSet> visual_hull(const GridSpec& grid, std::span<const View> views,
                                 const CutOptions& options = {});

}  // namespace studio::hull

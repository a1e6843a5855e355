#pragma once
// The line-segment representation of the visual hull (Grau, Pullen, Thomas, TCSVT 2004, §IV-B).
//
// A GridSpec lays a 2-D grid of columns over an axis-aligned box. One axis of the box is the
// continuous one (`axis`); the other two are sampled: grid coordinate i runs along axis u =
// (axis+1)%3 and j along axis v = (axis+2)%3, so that e_u x e_v = e_axis (right-handed). Column
// (i, j) is the 3-D line through the cell centre
//     x(t) = box_min + ((i+0.5) du) e_u + ((j+0.5) dv) e_v + (t - box_min[axis]) e_axis,
// parametrised by t, the world coordinate along the continuous axis.
//
// A SegmentSet holds, for every column, a sorted list of disjoint, non-touching intervals
// [lo, hi) in t (lo < hi). Storage is compressed rows: the intervals of column c = i + j*cells_u
// are intervals()[start()[c] .. start()[c+1]).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::hull {

enum class Axis : int { x = 0, y = 1, z = 2 };

struct Interval {
  float lo;
  float hi;
  friend bool operator==(const Interval&, const Interval&) = default;
};

struct GridSpec {
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_max = Eigen::Vector3d::Ones();
  Axis axis = Axis::y;  // the continuous axis
  int cells_u = 64;     // columns along axis u = (axis+1)%3
  int cells_v = 64;     // columns along axis v = (axis+2)%3

  // One line naming the problem: empty or inverted box, non-finite corners, cells < 1 or > 8192.
  Expected<void> validate() const;

  int a() const { return int(axis); }
  int u() const { return (int(axis) + 1) % 3; }
  int v() const { return (int(axis) + 2) % 3; }
  double du() const { return (box_max[u()] - box_min[u()]) / cells_u; }
  double dv() const { return (box_max[v()] - box_min[v()]) / cells_v; }
  double t_min() const { return box_min[a()]; }
  double t_max() const { return box_max[a()]; }
  std::size_t columns() const { return std::size_t(cells_u) * std::size_t(cells_v); }
  // World point of column (i, j) at parameter t.
  Eigen::Vector3d point(double i, double j, double t) const;

  // Declared here, before SegmentSet's defaulted ==, which needs it (clang rejects it otherwise).
  friend bool operator==(const GridSpec& a, const GridSpec& b) {
    return a.box_min == b.box_min && a.box_max == b.box_max && a.axis == b.axis &&
           a.cells_u == b.cells_u && a.cells_v == b.cells_v;
  }
};

class SegmentSet {
 public:
  SegmentSet() = default;
  // Every column holds the full range [t_min, t_max) (the hull before any cut).
  static SegmentSet full(const GridSpec& grid);
  // Every column empty.
  static SegmentSet empty(const GridSpec& grid);
  // From per-column lists (each sorted, disjoint; touching intervals are merged, empty dropped).
  static SegmentSet from_columns(const GridSpec& grid,
                                 const std::vector<std::vector<Interval>>& columns);

  const GridSpec& grid() const { return grid_; }
  std::size_t column_index(int i, int j) const { return std::size_t(i) + std::size_t(j) * grid_.cells_u; }
  std::span<const Interval> column(std::size_t c) const {
    return {intervals_.data() + start_[c], intervals_.data() + start_[c + 1]};
  }
  std::span<const Interval> column(int i, int j) const { return column(column_index(i, j)); }
  const std::vector<Interval>& intervals() const { return intervals_; }
  const std::vector<uint32_t>& start() const { return start_; }
  std::size_t interval_count() const { return intervals_.size(); }

  // Sum of interval lengths times the cell area (m^3 when the box is in metres).
  double volume() const;
  // Whether a world point lies inside: nearest column (cell containing the point), then its
  // intervals.
  bool contains(const Eigen::Vector3d& x_in_world) const;
  bool valid() const;  // the invariants above

  // Replace all intervals (used by the cut): starts has columns()+1 entries.
  void assign(std::vector<Interval> intervals, std::vector<uint32_t> starts);

  friend bool operator==(const SegmentSet&, const SegmentSet&) = default;

 private:
  GridSpec grid_;
  std::vector<Interval> intervals_;
  std::vector<uint32_t> start_;
};

// Connected components: two intervals are connected when their columns are 4-neighbours and
// their t-ranges overlap (share a positive length). Components are returned largest volume first,
// each as a SegmentSet over the same grid; components below min_volume are dropped. Separate
// actors in the studio come out as separate components.
std::vector<SegmentSet> connected_components(const SegmentSet& set, double min_volume = 0);

Expected<Axis> parse_axis(const std::string& name);
const char* axis_name(Axis axis);

}  // namespace studio::hull

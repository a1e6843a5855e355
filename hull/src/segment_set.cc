#include "hull/segment_set.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <numeric>

namespace studio::hull {

Expected<void> GridSpec::validate() const {
  if (!box_min.allFinite() || !box_max.allFinite()) return fail("box: corners must be finite numbers");
  for (int k = 0; k < 3; ++k) {
    if (!(box_max[k] > box_min[k])) {
      std::ostringstream m;
      m << "box: empty along " << "xyz"[k] << " (" << box_min[k] << " .. " << box_max[k]
        << "); need min < max on every axis";
      return fail(m.str());
    }
  }
  if (cells_u < 1 || cells_v < 1 || cells_u > 8192 || cells_v > 8192) {
    return fail("grid: " + std::to_string(cells_u) + "x" + std::to_string(cells_v) +
                " columns; each side must be 1..8192");
  }
  return {};
}

Eigen::Vector3d GridSpec::point(double i, double j, double t) const {
  Eigen::Vector3d x;
  x[u()] = box_min[u()] + (i + 0.5) * du();
  x[v()] = box_min[v()] + (j + 0.5) * dv();
  x[a()] = t;
  return x;
}

SegmentSet SegmentSet::full(const GridSpec& grid) {
  SegmentSet s;
  s.grid_ = grid;
  const std::size_t n = grid.columns();
  s.intervals_.assign(n, Interval{float(grid.t_min()), float(grid.t_max())});
  s.start_.resize(n + 1);
  std::iota(s.start_.begin(), s.start_.end(), 0u);
  return s;
}

SegmentSet SegmentSet::empty(const GridSpec& grid) {
  SegmentSet s;
  s.grid_ = grid;
  s.start_.assign(grid.columns() + 1, 0);
  return s;
}

SegmentSet SegmentSet::from_columns(const GridSpec& grid,
                                    const std::vector<std::vector<Interval>>& columns) {
  SegmentSet s = empty(grid);
  for (std::size_t c = 0; c < grid.columns() && c < columns.size(); ++c) {
    for (const Interval& iv : columns[c]) {
      if (!(iv.hi > iv.lo)) continue;
      if (s.intervals_.size() > s.start_[c] && s.intervals_.back().hi >= iv.lo) {
        s.intervals_.back().hi = std::max(s.intervals_.back().hi, iv.hi);
      } else {
        s.intervals_.push_back(iv);
      }
    }
    s.start_[c + 1] = uint32_t(s.intervals_.size());
  }
  for (std::size_t c = columns.size(); c < grid.columns(); ++c) s.start_[c + 1] = s.start_[c];
  return s;
}

double SegmentSet::volume() const {
  double length = 0;
  for (const Interval& iv : intervals_) length += double(iv.hi) - double(iv.lo);
  return length * grid_.du() * grid_.dv();
}

bool SegmentSet::contains(const Eigen::Vector3d& x) const {
  const int i = int(std::floor((x[grid_.u()] - grid_.box_min[grid_.u()]) / grid_.du()));
  const int j = int(std::floor((x[grid_.v()] - grid_.box_min[grid_.v()]) / grid_.dv()));
  if (i < 0 || j < 0 || i >= grid_.cells_u || j >= grid_.cells_v) return false;
  const double t = x[grid_.a()];
  for (const Interval& iv : column(i, j)) {
    if (t >= iv.lo && t < iv.hi) return true;
  }
  return false;
}

bool SegmentSet::valid() const {
  if (start_.size() != grid_.columns() + 1 || start_.front() != 0 || start_.back() != intervals_.size()) {
    return false;
  }
  for (std::size_t c = 0; c < grid_.columns(); ++c) {
    if (start_[c + 1] < start_[c]) return false;
    auto col = column(c);
    for (std::size_t k = 0; k < col.size(); ++k) {
      if (!(col[k].lo < col[k].hi)) return false;
      if (k > 0 && !(col[k - 1].hi < col[k].lo)) return false;
    }
  }
  return true;
}

void SegmentSet::assign(std::vector<Interval> intervals, std::vector<uint32_t> starts) {
  intervals_ = std::move(intervals);
  start_ = std::move(starts);
}

namespace {
struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Unite overlapping intervals of two columns (both sorted).
void unite_columns(const SegmentSet& s, std::size_t c0, std::size_t c1, UnionFind& uf) {
  const auto a = s.column(c0), b = s.column(c1);
  std::size_t p = 0, q = 0;
  while (p < a.size() && q < b.size()) {
    if (std::min(a[p].hi, b[q].hi) > std::max(a[p].lo, b[q].lo)) {
      uf.unite(uint32_t(s.start()[c0] + p), uint32_t(s.start()[c1] + q));
    }
    if (a[p].hi < b[q].hi) ++p; else ++q;
  }
}
}  // namespace

std::vector<SegmentSet> connected_components(const SegmentSet& set, double min_volume) {
  const GridSpec& g = set.grid();
  UnionFind uf(set.interval_count());
  for (int j = 0; j < g.cells_v; ++j) {
    for (int i = 0; i < g.cells_u; ++i) {
      const std::size_t c = set.column_index(i, j);
      if (i + 1 < g.cells_u) unite_columns(set, c, c + 1, uf);
      if (j + 1 < g.cells_v) unite_columns(set, c, c + g.cells_u, uf);
    }
  }
  std::vector<int> label(set.interval_count(), -1);
  std::vector<double> length;
  for (uint32_t k = 0; k < set.interval_count(); ++k) {
    const uint32_t r = uf.find(k);
    if (label[r] < 0) {
      label[r] = int(length.size());
      length.push_back(0);
    }
    label[k] = label[r];
    length[label[k]] += double(set.intervals()[k].hi) - set.intervals()[k].lo;
  }
  const double area = g.du() * g.dv();
  std::vector<int> order(length.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return length[a] > length[b]; });
  std::vector<int> rank(length.size(), -1);
  int kept = 0;
  for (int l : order) {
    if (length[l] * area >= min_volume) rank[l] = kept++;
  }
  std::vector<std::vector<Interval>> ivs(kept);
  std::vector<std::vector<uint32_t>> starts(kept, std::vector<uint32_t>(g.columns() + 1, 0));
  for (std::size_t c = 0; c < g.columns(); ++c) {
    for (uint32_t k = set.start()[c]; k < set.start()[c + 1]; ++k) {
      const int r = rank[label[k]];
      if (r >= 0) ivs[r].push_back(set.intervals()[k]);
    }
    for (int r = 0; r < kept; ++r) starts[r][c + 1] = uint32_t(ivs[r].size());
  }
  std::vector<SegmentSet> out;
  for (int r = 0; r < kept; ++r) {
    SegmentSet s = SegmentSet::empty(g);
    s.assign(std::move(ivs[r]), std::move(starts[r]));
    out.push_back(std::move(s));
  }
  return out;
}

Expected<Axis> parse_axis(const std::string& name) {
  if (name == "x") return Axis::x;
  if (name == "y") return Axis::y;
  if (name == "z") return Axis::z;
  return fail("axis '" + name + "': expected x, y or z");
}

const char* axis_name(Axis axis) { return axis == Axis::x ? "x" : axis == Axis::y ? "y" : "z"; }

}  // namespace studio::hull

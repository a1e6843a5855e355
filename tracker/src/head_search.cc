#include "tracker/head_search.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace studio::tracker {
namespace {

// Position order for ties: (x, z, y) lexicographic, the grid's storage order.
bool before(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  return std::tie(a.x(), a.z(), a.y()) < std::tie(b.x(), b.z(), b.y());
}

}  // namespace

Expected<void> HeadSearchOptions::validate() const {
  if (!(head_box.array() > 0).all() || !head_box.allFinite())
    return fail("tracker: head_box must be three positive sizes in metres");
  if (!outer_box.allFinite() || (outer_box.array() < head_box.array()).any())
    return fail("tracker: outer_box must contain head_box on every axis");
  if (!(head_diameter > 0) || !std::isfinite(head_diameter))
    return fail("tracker: head_diameter must be positive");
  if (!(min_confidence > 0 && min_confidence <= 1))
    return fail("tracker: min_confidence must be in (0, 1]");
  if (!(suppression_radius >= 0) || !std::isfinite(suppression_radius))
    return fail("tracker: suppression_radius must be >= 0");
  if (max_heads < 1) return fail("tracker: max_heads must be >= 1");
  if (!(refine_radius >= 0) || !std::isfinite(refine_radius) || refine_iterations < 0)
    return fail("tracker: refine_radius and refine_iterations must be >= 0");
  return {};
}

Expected<HeadSearch> HeadSearch::create(const HeadSearchOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  return HeadSearch(options);
}

bool HeadSearch::prepare(const OccupancyGrid& grid) {
  voxel_ = grid.voxel();
  for (int a = 0; a < 3; ++a) {
    s2_[a] = std::max(1, int(std::lround(options_.head_box[a] / voxel_[a])));
    const int m = std::max(
        0, int(std::lround((options_.outer_box[a] - options_.head_box[a]) / 2 / voxel_[a])));
    m_lo_[a] = m;
    m_hi_[a] = m;
  }
  if (options_.exclude_below) m_lo_.y() = 0;
  const double r = options_.head_diameter / 2;
  const double head_volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  reference_ = head_volume / grid.voxel_volume() * OccupancyGrid::kFull;
  threshold_ = std::max<int64_t>(1, int64_t(std::ceil(options_.min_confidence * reference_)));
  stats_ = {};
  stats_.grid_voxels = int64_t(grid.size());
  accepted_.clear();
  if (grid.empty()) {
    integral_.build(grid);
    return false;
  }
  integral_.build(grid);
  return integral_.total() > 0;
}

int64_t HeadSearch::score_at(const Eigen::Vector3i& p) const {
  const int64_t a2 = integral_.count(p, p + s2_);
  const int64_t a1 = integral_.count(p - m_lo_, p + s2_ + m_hi_);
  return 2 * a2 - a1;
}

int64_t HeadSearch::bound(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) const {
  const int64_t u2 = integral_.count(lo, hi + s2_);
  const int64_t i1 = integral_.count(hi - m_lo_, lo + s2_ + m_hi_);
  return std::min(u2, 2 * u2 - i1);
}

bool HeadSearch::suppressed(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                            bool whole) const {
  // V2 centres (x2 in voxel units): p + s2/2. Compare in metres, horizontally.
  const double r2 = options_.suppression_radius * options_.suppression_radius;
  for (const Eigen::Vector3i& a : accepted_) {
    double dx, dz;
    if (whole) {  // farthest point of the block from a
      dx = std::max(std::abs(lo.x() - a.x()), std::abs(hi.x() - a.x())) * voxel_.x();
      dz = std::max(std::abs(lo.z() - a.z()), std::abs(hi.z() - a.z())) * voxel_.z();
    } else {  // the leaf lo == hi
      dx = (lo.x() - a.x()) * voxel_.x();
      dz = (lo.z() - a.z()) * voxel_.z();
    }
    if (dx * dx + dz * dz < r2) return true;
  }
  return false;
}

HeadDetection HeadSearch::make_detection(const OccupancyGrid& grid, const Eigen::Vector3i& p,
                                         int64_t score) const {
  HeadDetection d;
  d.score = double(score) / OccupancyGrid::kFull * grid.voxel_volume();
  d.confidence = std::clamp(double(score) / reference_, 0.0, 1.0);
  d.box_min = grid.point(p.cast<double>());
  d.box_max = grid.point((p + s2_).cast<double>());
  // Occupancy centroid of V2 (voxel coordinates; voxel i has centre i + 0.5).
  const Eigen::Vector3i lo = p.cwiseMax(0), hi = (p + s2_).cwiseMin(grid.dims());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double w = 0;
  for (int x = lo.x(); x < hi.x(); ++x)
    for (int z = lo.z(); z < hi.z(); ++z) {
      const auto col = grid.column(x, z);
      for (int y = lo.y(); y < hi.y(); ++y) {
        const double v = col[std::size_t(y)];
        sum += v * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
        w += v;
      }
    }
  Eigen::Vector3d c =
      w > 0 ? Eigen::Vector3d(sum / w) : (p.cast<double>() + s2_.cast<double>() / 2);
  // Mean shift with a ball kernel kept inside V2 (so it cannot slide down the neck onto the
  // torso): the centroid of the occupancy of V2 within refine_radius of c.
  const Eigen::Vector3d rv =
      Eigen::Vector3d::Constant(options_.refine_radius).cwiseQuotient(voxel_);
  for (int it = 0; it < options_.refine_iterations && options_.refine_radius > 0; ++it) {
    const Eigen::Vector3i blo = (c - rv).array().floor().cast<int>().matrix().cwiseMax(lo);
    const Eigen::Vector3i bhi = ((c + rv).array().ceil().cast<int>().matrix()).cwiseMin(hi);
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    double ws = 0;
    for (int x = blo.x(); x < bhi.x(); ++x)
      for (int z = blo.z(); z < bhi.z(); ++z) {
        const double dx = (x + 0.5 - c.x()) / rv.x(), dz = (z + 0.5 - c.z()) / rv.z();
        const double h = 1 - dx * dx - dz * dz;
        if (h <= 0) continue;
        const auto col = grid.column(x, z);
        for (int y = blo.y(); y < bhi.y(); ++y) {
          const double dy = (y + 0.5 - c.y()) / rv.y();
          if (dy * dy >= h) continue;
          const double v = col[std::size_t(y)];
          s += v * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
          ws += v;
        }
      }
    if (ws <= 0) break;
    const Eigen::Vector3d next = s / ws;
    const bool done = (next - c).cwiseProduct(voxel_).norm() < 1e-4;
    c = next;
    if (done) break;
  }
  d.position = grid.point(c);
  return d;
}

std::vector<HeadDetection> HeadSearch::find(const OccupancyGrid& grid) {
  std::vector<HeadDetection> heads;
  if (!prepare(grid)) return heads;
  // Max-heap on (bound, earliest lo): a leaf pops only when no block can hold a better or
  // equal-and-earlier position, so leaves come out in the exhaustive order.
  const auto less = [](const Block& a, const Block& b) {
    return a.bound < b.bound || (a.bound == b.bound && before(b.lo, a.lo));
  };
  heap_.clear();
  const Eigen::Vector3i root_lo = Eigen::Vector3i::Ones() - s2_;
  const Eigen::Vector3i root_hi = grid.dims() - Eigen::Vector3i::Ones();
  heap_.push_back({bound(root_lo, root_hi), root_lo, root_hi});
  stats_.bounds = 1;
  while (!heap_.empty()) {
    std::pop_heap(heap_.begin(), heap_.end(), less);
    const Block b = heap_.back();
    heap_.pop_back();
    if (b.bound < threshold_) break;
    if (b.lo == b.hi) {
      if (suppressed(b.lo, b.hi, false)) continue;
      accepted_.push_back(b.lo);
      heads.push_back(make_detection(grid, b.lo, b.bound));
      if (int(heads.size()) >= options_.max_heads) break;
      continue;
    }
    int axis = 0;
    const Eigen::Vector3i ext = b.hi - b.lo;
    ext.maxCoeff(&axis);
    const int mid = b.lo[axis] + ext[axis] / 2;
    Eigen::Vector3i hi_a = b.hi, lo_b = b.lo;
    hi_a[axis] = mid;
    lo_b[axis] = mid + 1;
    for (const auto& [lo, hi] : {std::pair{b.lo, hi_a}, std::pair{lo_b, b.hi}}) {
      const int64_t ub = bound(lo, hi);
      ++stats_.bounds;
      if (ub < threshold_ || (!accepted_.empty() && suppressed(lo, hi, true))) continue;
      heap_.push_back({ub, lo, hi});
      std::push_heap(heap_.begin(), heap_.end(), less);
    }
  }
  return heads;
}

std::vector<HeadDetection> HeadSearch::find_exhaustive(const OccupancyGrid& grid) {
  std::vector<HeadDetection> heads;
  if (!prepare(grid)) return heads;
  struct Candidate {
    int64_t score;
    Eigen::Vector3i p;
  };
  std::vector<Candidate> candidates;
  const Eigen::Vector3i lo = Eigen::Vector3i::Ones() - s2_;
  const Eigen::Vector3i n = grid.dims();
  for (int x = lo.x(); x < n.x(); ++x)
    for (int z = lo.z(); z < n.z(); ++z)
      for (int y = lo.y(); y < n.y(); ++y) {
        const Eigen::Vector3i p(x, y, z);
        const int64_t m = score_at(p);
        ++stats_.bounds;
        if (m >= threshold_) candidates.push_back({m, p});
      }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.score > b.score || (a.score == b.score && before(a.p, b.p));
  });
  for (const Candidate& c : candidates) {
    if (suppressed(c.p, c.p, false)) continue;
    accepted_.push_back(c.p);
    heads.push_back(make_detection(grid, c.p, c.score));
    if (int(heads.size()) >= options_.max_heads) break;
  }
  return heads;
}

}  // namespace studio::tracker

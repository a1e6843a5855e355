#include "keyer/cleanup.h"

#include <numeric>

namespace studio::keyer {
namespace {

uint32_t find(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

void unite(std::vector<uint32_t>& parent, uint32_t a, uint32_t b) {
  a = find(parent, a);
  b = find(parent, b);
  if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

// Union-find labels of the runs of `m`; afterwards find(parent, i) is run i's component.
void label_runs(const RunMask& m, bool eight_connected, std::vector<uint32_t>& parent) {
  const auto& runs = m.runs();
  const auto& start = m.row_start();
  parent.resize(runs.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const int32_t touch = eight_connected ? 1 : 0;  // 8-connected runs may meet diagonally
  for (int y = 1; y < m.height(); ++y) {
    uint32_t i = start[y], j = start[y - 1];
    const uint32_t i_end = start[y + 1], j_end = start[y];
    while (i < i_end && j < j_end) {
      const Run& a = runs[i];
      const Run& b = runs[j];
      if (a.begin < b.end + touch && b.begin < a.end + touch) unite(parent, i, j);
      if (a.end < b.end) ++i; else ++j;
    }
  }
}

}  // namespace

CleanupStats clean_mask(const RunMask& in, const CleanupOptions& options, RunMask& out,
                        CleanupScratch& s) {
  return clean_mask(in, options, out, s, nullptr, nullptr);
}

CleanupStats clean_mask(const RunMask& in, const CleanupOptions& options, RunMask& out,
                        CleanupScratch& s, ShowsBackingFn shows_backing, const void* context) {
  CleanupStats stats;
  const int w = in.width(), h = in.height();
  auto reset = [&](RunMask& m) {
    if (m.width() == w && m.height() == h) m.clear(); else m = RunMask(w, h);
  };

  // 1. Remove small foreground components (8-connected).
  const RunMask* fg = &in;
  if (options.min_component_area > 1 && !in.runs().empty()) {
    label_runs(in, /*eight_connected=*/true, s.parent);
    const auto& runs = in.runs();
    s.area.assign(runs.size(), 0);
    for (uint32_t i = 0; i < runs.size(); ++i)
      s.area[find(s.parent, i)] += uint64_t(runs[i].end - runs[i].begin);
    reset(s.kept);
    for (int y = 0; y < h; ++y)
      for (uint32_t i = in.row_start()[y]; i < in.row_start()[y + 1]; ++i)
        if (s.area[find(s.parent, i)] >= uint64_t(options.min_component_area))
          s.kept.push_run(y, runs[i].begin, runs[i].end);
    s.kept.finish();
    for (uint32_t i = 0; i < runs.size(); ++i)
      if (s.parent[i] == i && s.area[i] < uint64_t(options.min_component_area))
        ++stats.components_removed;
    fg = &s.kept;
  }

  reset(out);
  if (options.max_hole_area <= 0 || fg->runs().empty()) {
    for (int y = 0; y < h; ++y)
      for (const Run& r : fg->row(y)) out.push_run(y, r.begin, r.end);
    out.finish();
    return stats;
  }

  // 2. Fill holes: background components (4-connected) off the border, small enough.
  reset(s.gaps);
  for (int y = 0; y < h; ++y) {
    int32_t x = 0;
    for (const Run& r : fg->row(y)) {
      if (r.begin > x) s.gaps.push_run(y, x, r.begin);
      x = r.end;
    }
    if (x < w) s.gaps.push_run(y, x, w);
  }
  s.gaps.finish();
  label_runs(s.gaps, /*eight_connected=*/false, s.parent);
  const auto& gaps = s.gaps.runs();
  s.area.assign(gaps.size(), 0);
  s.flags.assign(gaps.size(), 0);  // 1 = touches the border, 2 = shows the clean backing
  for (int y = 0; y < h; ++y)
    for (uint32_t i = s.gaps.row_start()[y]; i < s.gaps.row_start()[y + 1]; ++i) {
      const uint32_t root = find(s.parent, i);
      s.area[root] += uint64_t(gaps[i].end - gaps[i].begin);
      if (y == 0 || y == h - 1 || gaps[i].begin == 0 || gaps[i].end == w) s.flags[root] = 1;
    }
  auto filled = [&](uint32_t gap) {
    const uint32_t root = find(s.parent, gap);
    return !s.flags[root] && s.area[root] <= uint64_t(options.max_hole_area);
  };
  if (shows_backing) {
    for (int y = 0; y < h; ++y)
      for (uint32_t i = s.gaps.row_start()[y]; i < s.gaps.row_start()[y + 1]; ++i) {
        if (!filled(i)) continue;  // too big, on the border, or already known to show backing
        if (shows_backing(context, y, gaps[i].begin, gaps[i].end)) {
          s.flags[find(s.parent, i)] = 2;
          ++stats.gaps_kept;
        }
      }
  }
  for (uint32_t i = 0; i < gaps.size(); ++i)
    if (s.parent[i] == i && filled(i)) ++stats.holes_filled;

  for (int y = 0; y < h; ++y) {
    const auto row = fg->row(y);
    if (row.empty()) continue;
    uint32_t gap = s.gaps.row_start()[y] + (row.front().begin > 0 ? 1 : 0);  // first inner gap
    Run cur = row.front();
    for (std::size_t k = 1; k < row.size(); ++k, ++gap) {
      if (filled(gap)) {
        cur.end = row[k].end;
      } else {
        out.push_run(y, cur.begin, cur.end);
        cur = row[k];
      }
    }
    out.push_run(y, cur.begin, cur.end);
  }
  out.finish();
  return stats;
}

}  // namespace studio::keyer

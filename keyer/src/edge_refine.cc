#include "keyer/edge_refine.h"

#include <algorithm>
#include <cstdint>
#include <span>

namespace studio::keyer {
namespace {

template <class Px>
class Refiner {
 public:
  using Flip = EdgeRefineScratch::Flip;
  Refiner(ImageView<const Px> image, const RunMask& in, const EdgeRefineOptions& options)
      : image_(image), in_(in), threshold_(options.threshold),
        min_contrast2_(double(options.min_contrast) * options.min_contrast) {}

  // Decisions on pixels of row `row` go to `rows[0]`, of row `row + 1` to `rows[1]`.
  void set_rows(int row, std::vector<Flip>* current, std::vector<Flip>* next) {
    row_ = row;
    rows_[0] = current;
    rows_[1] = next;
  }

  // Re-decides p (actor) and q = p + (dx, dy) (backing) from F = p - d and B = q + d.
  void transition(int px, int py, int dx, int dy) {
    const int qx = px + dx, qy = py + dy;
    const int fx = px - dx, fy = py - dy, bx = qx + dx, by = qy + dy;
    if (!inside(fx, fy) || !inside(bx, by)) return;
    if (!in_.contains(fx, fy) || in_.contains(bx, by)) return;  // outer pixels must be pure
    const uint8_t* F = at(fx, fy);
    const uint8_t* B = at(bx, by);
    int d[3], dd = 0;
    for (int k = 0; k < 3; ++k) {
      d[k] = int(F[k]) - int(B[k]);
      dd += d[k] * d[k];
    }
    if (dd < min_contrast2_) return;
    const double cut = threshold_ * dd;  // c(x) >= threshold  <=>  (I(x) - I(B)) . d >= cut
    auto projection = [&](int x, int y) {
      const uint8_t* I = at(x, y);
      int e = 0;
      for (int k = 0; k < 3; ++k) e += (int(I[k]) - int(B[k])) * d[k];
      return double(e);
    };
    // Along a row, push in increasing x so that each stream of a row's decisions stays sorted.
    const Flip p{px, dd, projection(px, py) >= cut, true};
    const Flip q{qx, dd, projection(qx, qy) >= cut, false};
    if (dx < 0) {
      rows_[0]->push_back(q);
      rows_[0]->push_back(p);
    } else {
      rows_[py - row_]->push_back(p);
      rows_[qy - row_]->push_back(q);
    }
  }

 private:
  bool inside(int x, int y) const {
    return x >= 0 && y >= 0 && x < in_.width() && y < in_.height();
  }
  const uint8_t* at(int x, int y) const {
    return reinterpret_cast<const uint8_t*>(image_.row(y) + x);
  }

  ImageView<const Px> image_;
  const RunMask& in_;
  double threshold_, min_contrast2_;
  int row_ = 0;
  std::vector<Flip>* rows_[2] = {nullptr, nullptr};
};

// Row `runs` with the sorted flips of that row applied, into `out` (runs kept sorted, disjoint and
// not touching). Flips that do not change the pixel are ignored.
void apply_flips(std::span<const Run> runs, std::span<const EdgeRefineScratch::Flip> flips,
                 std::vector<Run>& out) {
  out.clear();
  auto emit = [&](int32_t b, int32_t e) {
    if (b >= e) return;
    if (!out.empty() && out.back().end >= b) {
      out.back().end = std::max(out.back().end, e);
    } else {
      out.push_back({b, e});
    }
  };
  std::size_t j = 0;
  for (const Run& r : runs) {
    for (; j < flips.size() && flips[j].x < r.begin; ++j) {
      if (flips[j].actor) emit(flips[j].x, flips[j].x + 1);
    }
    int32_t b = r.begin;
    for (; j < flips.size() && flips[j].x < r.end; ++j) {
      if (flips[j].actor) continue;
      emit(b, flips[j].x);
      b = flips[j].x + 1;
    }
    emit(b, r.end);
  }
  for (; j < flips.size(); ++j) {
    if (flips[j].actor) emit(flips[j].x, flips[j].x + 1);
  }
}

// A row's decisions arrive as three runs sorted by x: [0, s1) from the transitions to the row
// above, [s1, s2) from the row's own run ends, [s2, end) from the transitions to the row below.
// Merges them into `out`, keeping one decision per pixel (the transition with the largest
// contrast; ties: actor) and only the decisions that change the pixel.
void resolve(const std::vector<EdgeRefineScratch::Flip>& row, std::size_t s1, std::size_t s2,
             std::vector<EdgeRefineScratch::Flip>& out) {
  using Flip = EdgeRefineScratch::Flip;
  out.clear();
  std::size_t i[3] = {0, s1, s2};
  const std::size_t e[3] = {s1, s2, row.size()};
  auto better = [](const Flip& a, const Flip& b) {
    return a.contrast != b.contrast ? a.contrast > b.contrast : a.actor && !b.actor;
  };
  for (;;) {
    int pick = -1;
    for (int k = 0; k < 3; ++k) {
      if (i[k] < e[k] && (pick < 0 || row[i[k]].x < row[i[pick]].x)) pick = k;
    }
    if (pick < 0) break;
    Flip best = row[i[pick]];
    for (int k = 0; k < 3; ++k) {
      for (; i[k] < e[k] && row[i[k]].x == best.x; ++i[k]) {
        if (better(row[i[k]], best)) best = row[i[k]];
      }
    }
    if (best.actor != best.was_actor) out.push_back(best);
  }
}

template <class Px>
EdgeRefineStats refine_impl(ImageView<const Px> image, const RunMask& in,
                            const EdgeRefineOptions& options, RunMask& out,
                            EdgeRefineScratch& scratch) {
  const int w = in.width(), h = in.height();
  if (out.width() == w && out.height() == h) {
    out.clear();
  } else {
    out = RunMask(w, h);
  }
  EdgeRefineStats stats;
  Refiner<Px> refiner(image, in, options);
  auto* current = &scratch.current;
  auto* next = &scratch.next;
  current->clear();
  next->clear();
  // Row by row: row y's decisions come from its own runs' ends and from the transitions to rows
  // y - 1 (made in the previous step) and y + 1; once those are made, row y is final.
  for (int y = 0; y < h; ++y) {
    refiner.set_rows(y, current, next);
    const std::size_t s1 = current->size();
    // Transitions along the row: the ends of its runs.
    for (const Run& r : in.row(y)) {
      if (r.begin > 0) refiner.transition(r.begin, y, -1, 0);
      if (r.end < w) refiner.transition(r.end - 1, y, 1, 0);
    }
    const std::size_t s2 = current->size();
    if (y + 1 < h) {
      // Transitions between rows y and y + 1: where exactly one of them is actor. Membership of
      // each row toggles at its runs' ends, so the difference toggles at the merged ends.
      const auto a = in.row(y), b = in.row(y + 1);
      auto end_at = [](std::span<const Run> r, std::size_t k) {
        return k % 2 == 0 ? r[k / 2].begin : r[k / 2].end;
      };
      std::size_t i = 0, j = 0;
      bool a_in = false, b_in = false;
      int32_t from = 0;
      while (i < 2 * a.size() || j < 2 * b.size()) {
        const int32_t xa = i < 2 * a.size() ? end_at(a, i) : INT32_MAX;
        const int32_t xb = j < 2 * b.size() ? end_at(b, j) : INT32_MAX;
        const int32_t x = std::min(xa, xb);
        if (a_in != b_in) {  // [from, x) differs between the rows
          for (int32_t u = from; u < x; ++u) {
            if (a_in) {
              refiner.transition(u, y, 0, 1);
            } else {
              refiner.transition(u, y + 1, 0, -1);
            }
          }
        }
        if (xa == x) {
          a_in = !a_in;
          ++i;
        }
        if (xb == x) {
          b_in = !b_in;
          ++j;
        }
        from = x;
      }
    }
    resolve(*current, s1, s2, scratch.resolved);
    if (scratch.resolved.empty()) {
      for (const Run& r : in.row(y)) out.push_run(y, r.begin, r.end);
    } else {
      for (const auto& f : scratch.resolved) (f.actor ? stats.added : stats.removed) += 1;
      apply_flips(in.row(y), scratch.resolved, scratch.row);
      for (const Run& r : scratch.row) out.push_run(y, r.begin, r.end);
    }
    std::swap(current, next);
    next->clear();
  }
  out.finish();
  return stats;
}

}  // namespace

EdgeRefineStats refine_edges(ImageView<const Rgb8> image, const RunMask& in,
                             const EdgeRefineOptions& options, RunMask& out,
                             EdgeRefineScratch& scratch) {
  return refine_impl(image, in, options, out, scratch);
}
EdgeRefineStats refine_edges(ImageView<const Bgr8> image, const RunMask& in,
                             const EdgeRefineOptions& options, RunMask& out,
                             EdgeRefineScratch& scratch) {
  return refine_impl(image, in, options, out, scratch);
}

}  // namespace studio::keyer

#include "keyer/edge_refine.h"

#include <algorithm>
#include <cstdint>
#include <span>

namespace studio::keyer {
namespace {

template <class Px>
class Refiner {
 public:
  Refiner(ImageView<const Px> image, const RunMask& in, const EdgeRefineOptions& options,
          std::vector<EdgeRefineScratch::Flip>& flips)
      : image_(image), in_(in), flips_(flips),
        threshold_(options.threshold),
        min_contrast2_(double(options.min_contrast) * options.min_contrast) {}

  // Re-decides p (actor) and q = p + (dx, dy) (backing) from F = p - d and B = q + d.
  void transition(int px, int py, int dx, int dy) {
    const int qx = px + dx, qy = py + dy;
    const int fx = px - dx, fy = py - dy, bx = qx + dx, by = qy + dy;
    if (!inside(fx, fy) || !inside(bx, by)) return;
    if (!in_.contains(fx, fy) || in_.contains(bx, by)) return;  // outer pixels must be pure
    const uint8_t* F = at(fx, fy);
    const uint8_t* B = at(bx, by);
    // Integer colours: d, dd and the projections are exact in double.
    double d[3], dd = 0;
    for (int k = 0; k < 3; ++k) {
      d[k] = double(F[k]) - double(B[k]);
      dd += d[k] * d[k];
    }
    if (dd < min_contrast2_) return;
    const double cut = threshold_ * dd;  // c(x) >= threshold  <=>  (I(x) - I(B)) . d >= cut
    auto projection = [&](int x, int y) {
      const uint8_t* I = at(x, y);
      double e = 0;
      for (int k = 0; k < 3; ++k) e += (double(I[k]) - double(B[k])) * d[k];
      return e;
    };
    flips_.push_back({py, px, projection(px, py) >= cut, true, dd});
    flips_.push_back({qy, qx, projection(qx, qy) >= cut, false, dd});
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
  std::vector<EdgeRefineScratch::Flip>& flips_;
  double threshold_, min_contrast2_;
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

template <class Px>
EdgeRefineStats refine_impl(ImageView<const Px> image, const RunMask& in,
                            const EdgeRefineOptions& options, RunMask& out,
                            EdgeRefineScratch& scratch) {
  const int w = in.width(), h = in.height();
  auto& flips = scratch.flips;
  flips.clear();
  Refiner<Px> refiner(image, in, options, flips);
  for (int y = 0; y < h; ++y) {
    // Transitions along the row: the ends of its runs.
    for (const Run& r : in.row(y)) {
      if (r.begin > 0) refiner.transition(r.begin, y, -1, 0);
      if (r.end < w) refiner.transition(r.end - 1, y, 1, 0);
    }
    if (y + 1 == h) break;
    // Transitions between rows y and y + 1: where exactly one of them is actor. Membership of
    // each row toggles at its runs' ends, so the difference toggles at the merged ends.
    const auto a = in.row(y), b = in.row(y + 1);
    std::size_t i = 0, j = 0;
    bool a_in = false, b_in = false;
    int32_t from = 0;
    while (i < 2 * a.size() || j < 2 * b.size()) {
      auto end_at = [](std::span<const Run> r, std::size_t k) {
        return k % 2 == 0 ? r[k / 2].begin : r[k / 2].end;
      };
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
  // One decision per pixel: the transition with the largest contrast (ties: actor), then only
  // the decisions that change the pixel.
  std::sort(flips.begin(), flips.end(), [](const auto& a, const auto& b) {
    if (a.y != b.y) return a.y < b.y;
    if (a.x != b.x) return a.x < b.x;
    if (a.contrast != b.contrast) return a.contrast > b.contrast;
    return a.actor > b.actor;
  });
  flips.erase(std::unique(flips.begin(), flips.end(),
                          [](const auto& p, const auto& q) { return p.y == q.y && p.x == q.x; }),
              flips.end());
  flips.erase(std::remove_if(flips.begin(), flips.end(),
                             [](const auto& f) { return f.actor == f.was_actor; }),
              flips.end());
  EdgeRefineStats stats;
  if (out.width() == w && out.height() == h) {
    out.clear();
  } else {
    out = RunMask(w, h);
  }
  std::size_t k = 0;
  for (int y = 0; y < h; ++y) {
    const std::size_t first = k;
    while (k < flips.size() && flips[k].y == y) ++k;
    if (first == k) {
      for (const Run& r : in.row(y)) out.push_run(y, r.begin, r.end);
      continue;
    }
    for (std::size_t f = first; f < k; ++f) (flips[f].actor ? stats.added : stats.removed) += 1;
    apply_flips(in.row(y), {flips.data() + first, k - first}, scratch.row);
    for (const Run& r : scratch.row) out.push_run(y, r.begin, r.end);
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

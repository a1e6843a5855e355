#include "hull/viewpoint_cut.h"

#include <algorithm>
#include <thread>

#include "frustum.h"

namespace studio::hull {

Expected<void> ViewpointOptions::validate() const {
  if (step < 1 || step > 64) return fail("step: " + std::to_string(step) + " (need 1..64)");
  return cut.validate();
}

Expected<ViewpointCut> viewpoint_cut(const Camera& viewpoint, const Eigen::AlignedBox3d& box,
                                     std::span<const View> views, const ViewpointOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  if (viewpoint.width <= 0 || viewpoint.height <= 0) {
    return fail("viewpoint " + viewpoint.id + ": empty image size");
  }
  if (box.isEmpty()) return fail("box: empty");
  const Eigen::Vector3d C = viewpoint.centre_in_world();
  const Eigen::Vector4d X(C.x(), C.y(), C.z(), 1.0);  // every ray passes through the centre
  std::vector<PreparedView> prepared;
  for (const View& v : views) {
    auto p = PreparedView::create(*v.camera, *v.mask, X, options.cut);
    if (!p) return std::unexpected(p.error());
    prepared.push_back(std::move(*p));
  }
  ViewpointCut out;
  out.step = options.step;
  out.width = (viewpoint.width + options.step - 1) / options.step;
  out.height = (viewpoint.height + options.step - 1) / options.step;
  const int need = options.cut.required_views(views.size());
  const int T = std::clamp(options.cut.threads, 1, std::max(1, out.height / 8));
  std::vector<std::vector<Interval>> chunk_iv(T);
  std::vector<std::vector<uint32_t>> chunk_count(T);
  const auto work = [&](int chunk) {
    const int y0 = out.height * chunk / T, y1 = out.height * (chunk + 1) / T;
    CutScratch scratch;
    std::vector<Interval> a, b;
    std::vector<detail::Range> seen(prepared.size()), cover;
    std::vector<std::pair<double, int>> events;
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < out.width; ++x) {
        const Eigen::Vector2d pixel(x * options.step, y * options.step);
        const Eigen::Vector3d d = viewpoint.pixel_ray_in_world(pixel);
        // Ray-box clip (slab test), in front of the viewpoint.
        double t0 = 0, t1 = 1e300;
        for (int k = 0; k < 3; ++k) {
          if (d[k] == 0) {
            if (C[k] < box.min()[k] || C[k] > box.max()[k]) t0 = 1, t1 = 0;
            continue;
          }
          double p = (box.min()[k] - C[k]) / d[k], q = (box.max()[k] - C[k]) / d[k];
          if (p > q) std::swap(p, q);
          t0 = std::max(t0, p), t1 = std::min(t1, q);
        }
        const std::size_t before = chunk_iv[chunk].size();
        if (float(t0) < float(t1)) {
          // The visibility policy: only the parts seen by at least `need` views.
          const Interval whole{float(t0), float(t1)};
          for (std::size_t k = 0; k < prepared.size(); ++k) {
            const auto [lo, hi] = prepared[k].seen(C, d, whole.lo, whole.hi);
            seen[k] = {lo, hi};
          }
          cover.clear();
          detail::at_least(seen, need, whole.lo, whole.hi, &events, &cover);
          a.clear();
          detail::intersect(std::span<const Interval>(&whole, 1), cover, &a);
          for (const PreparedView& view : prepared) {
            b.clear();
            view.cut_line(C, d, a, &b, &scratch);
            std::swap(a, b);
            if (a.empty()) break;
          }
          chunk_iv[chunk].insert(chunk_iv[chunk].end(), a.begin(), a.end());
        }
        chunk_count[chunk].push_back(uint32_t(chunk_iv[chunk].size() - before));
      }
    }
  };
  {
    std::vector<std::jthread> workers;
    for (int k = 1; k < T; ++k) workers.emplace_back(work, k);
    work(0);
  }
  out.start.assign(std::size_t(out.width) * out.height + 1, 0);
  std::size_t c = 0;
  for (int k = 0; k < T; ++k) {
    out.intervals.insert(out.intervals.end(), chunk_iv[k].begin(), chunk_iv[k].end());
    for (uint32_t n : chunk_count[k]) {
      out.start[c + 1] = out.start[c] + n;
      ++c;
    }
  }
  out.coverage = RunMask(out.width, out.height);
  for (int y = 0; y < out.height; ++y) {
    int begin = -1;
    for (int x = 0; x <= out.width; ++x) {
      const std::size_t s = std::size_t(x) + std::size_t(y) * out.width;
      const bool on = x < out.width && out.start[s + 1] > out.start[s];
      if (on && begin < 0) begin = x;
      if (!on && begin >= 0) {
        out.coverage.push_run(y, begin, x);
        begin = -1;
      }
    }
  }
  out.coverage.finish();
  return out;
}

}  // namespace studio::hull

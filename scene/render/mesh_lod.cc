#include "mesh_lod.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>

namespace studio::scene_render {
namespace {

double longest_edge(const std::vector<Eigen::Vector3f>& p, const std::uint32_t* idx,
                    std::size_t count) {
  float longest = 0;
  for (std::size_t t = 0; t + 2 < count; t += 3)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, (p[idx[t + k]] - p[idx[t + (k + 1) % 3]]).squaredNorm());
  return std::sqrt(longest);
}

}  // namespace

MeshLods build_lods(const std::vector<Eigen::Vector3f>& positions,
                    const std::vector<std::uint32_t>& indices, const LodOptions& options) {
  MeshLods out;
  out.indices = indices;
  out.levels.push_back({0, static_cast<std::uint32_t>(indices.size()), 0.0f});
  if (indices.size() < 3 * options.min_triangles || positions.empty()) return out;
  const float* xyz = positions.front().data();
  const std::size_t stride = sizeof(Eigen::Vector3f);
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  const double scale = meshopt_simplifyScale(xyz, positions.size(), stride);
  const double edge_bound =
      std::max(longest_edge(positions, indices.data(), indices.size()), options.max_edge);
  std::vector<std::uint32_t> level(indices.size());
  std::size_t previous = indices.size();
  while (true) {
    const std::size_t target =
        static_cast<std::size_t>(double(previous) * options.reduction) / 3 * 3;
    if (target < 3 * 64) break;
    float error = 0;
    // From the full mesh each time (the best quality for a given size).
    const std::size_t n =
        meshopt_simplify(level.data(), indices.data(), indices.size(), xyz, positions.size(),
                         stride, target, static_cast<float>(options.max_error), 0, &error);
    if (n == 0 || double(n) > 0.8 * double(previous)) break;  // no real gain any more
    if (longest_edge(positions, level.data(), n) > edge_bound) break;
    out.levels.push_back({static_cast<std::uint32_t>(out.indices.size()),
                          static_cast<std::uint32_t>(n), static_cast<float>(error * scale)});
    out.indices.insert(out.indices.end(), level.begin(), level.begin() + std::ptrdiff_t(n));
    previous = n;
  }
  return out;
}

}  // namespace studio::scene_render

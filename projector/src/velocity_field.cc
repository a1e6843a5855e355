#include "projector/velocity_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace studio::projector {

Expected<VelocityField> VelocityField::create(const ActorMesh& fitted, const MeshMotion& motion,
                                              double cell_m) {
  if (fitted.vertices.empty()) return fail("velocity field: empty mesh");
  if (motion.vertex_region.size() != fitted.vertices.size())
    return fail("velocity field: the motion has " + std::to_string(motion.vertex_region.size()) +
                " vertices, the mesh " + std::to_string(fitted.vertices.size()));
  if (!(cell_m >= 1e-3 && cell_m <= 10)) return fail("velocity field: cell size 1 mm .. 10 m");
  VelocityField f;
  f.capture_ns_ = fitted.capture_ns;
  f.global_ = motion.global_velocity.cast<float>();
  f.inv_cell_ = float(1.0 / cell_m);
  Eigen::Vector3f lo = fitted.vertices.front(), hi = lo;
  for (const auto& v : fitted.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // One cell of border all round: a newer mesh's point just outside the fitted box still finds
  // the region next to it.
  f.origin_ = lo - Eigen::Vector3f::Constant(float(cell_m));
  for (int k = 0; k < 3; ++k)
    f.size_[k] = std::max(1, int(std::floor((hi[k] - f.origin_[k]) * f.inv_cell_)) + 2);
  const std::size_t cells = std::size_t(f.size_.x()) * f.size_.y() * f.size_.z();
  if (cells > (std::size_t(1) << 24)) return fail("velocity field: mesh too large for its cells");
  f.velocity_.reserve(motion.regions.size());
  for (const auto& r : motion.regions) f.velocity_.push_back(r.velocity.cast<float>());
  // Votes per cell and region: regions are few per cell (usually one), so a short list each.
  std::vector<std::vector<std::pair<int, int>>> votes(cells);
  std::vector<int> count(cells, 0);
  for (std::size_t i = 0; i < fitted.vertices.size(); ++i) {
    const int c = f.cell_of(fitted.vertices[i]);
    const int region = motion.vertex_region[i];
    if (c < 0 || region < 0 || std::size_t(region) >= f.velocity_.size()) continue;
    auto& list = votes[std::size_t(c)];
    auto it =
        std::find_if(list.begin(), list.end(), [&](const auto& e) { return e.first == region; });
    if (it == list.end())
      list.emplace_back(region, 1);
    else
      ++it->second;
    ++count[std::size_t(c)];
  }
  f.cell_region_.assign(cells, -1);
  for (std::size_t c = 0; c < cells; ++c) {
    int best = 0;
    for (const auto& [region, n] : votes[c])
      if (n > best) {
        best = n;
        f.cell_region_[c] = region;
      }
  }
  // Empty cells next to occupied ones: the neighbour holding most vertices lends its region.
  const int nx = f.size_.x(), ny = f.size_.y(), nz = f.size_.z();
  std::vector<int> filled = f.cell_region_;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const std::size_t c = (std::size_t(z) * ny + y) * nx + x;
        if (f.cell_region_[c] >= 0) continue;
        int best = 0;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int X = x + dx, Y = y + dy, Z = z + dz;
              if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
              const std::size_t d = (std::size_t(Z) * ny + Y) * nx + X;
              if (count[d] > best && f.cell_region_[d] >= 0) {
                best = count[d];
                filled[c] = f.cell_region_[d];
              }
            }
      }
  f.cell_region_ = std::move(filled);
  return f;
}

int VelocityField::cell_of(const Eigen::Vector3f& p) const {
  const Eigen::Vector3f q = (p - origin_) * inv_cell_;
  if (!(q.minCoeff() >= 0)) return -1;  // also NaN
  const int x = int(q.x()), y = int(q.y()), z = int(q.z());
  if (x >= size_.x() || y >= size_.y() || z >= size_.z()) return -1;
  return (z * size_.y() + y) * size_.x() + x;
}

Eigen::Vector3f VelocityField::at(const Eigen::Vector3f& p, double since_s) const {
  auto lookup = [&](const Eigen::Vector3f& q) {
    const int c = cell_of(q);
    const int region = c < 0 ? -1 : cell_region_[std::size_t(c)];
    return region < 0 ? global_ : velocity_[std::size_t(region)];
  };
  const Eigen::Vector3f v0 = lookup(p);
  return lookup(p - float(since_s) * v0);
}

Expected<std::vector<Eigen::Vector3f>> VelocityField::at(const ActorMesh& mesh) const {
  if (mesh.capture_ns < capture_ns_)
    return fail("velocity field: mesh captured before the fitted one");
  const double since_s = double(mesh.capture_ns - capture_ns_) * 1e-9;
  std::vector<Eigen::Vector3f> out(mesh.vertices.size(), Eigen::Vector3f::Zero());
  std::vector<char> done(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t i : t) {
      if (done[i]) continue;
      done[i] = 1;
      out[i] = at(mesh.vertices[i], since_s);
    }
  return out;
}

Expected<ActorMesh> predict_by_velocities(const ActorMesh& mesh,
                                          std::span<const Eigen::Vector3f> velocities,
                                          double horizon_s) {
  if (velocities.size() != mesh.vertices.size())
    return fail("predict: " + std::to_string(velocities.size()) + " velocities for " +
                std::to_string(mesh.vertices.size()) + " vertices");
  if (!(horizon_s >= 0) || !std::isfinite(horizon_s)) return fail("predict: horizon must be >= 0");
  ActorMesh out = mesh;
  const float h = float(horizon_s);
  for (std::size_t i = 0; i < out.vertices.size(); ++i) out.vertices[i] += h * velocities[i];
  return out;
}

}  // namespace studio::projector

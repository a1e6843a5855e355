#include "shapes.h"

#include <cmath>
#include <numbers>

namespace studio::scene_tools {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A (cols+1) x (rows+1) vertex lattice from a parametric surface: quads split in two triangles,
// wound so that the triangle normal agrees with the supplied vertex normal.
MeshBuild lattice(int cols, int rows,
                  const std::function<void(float, float, Eigen::Vector3f&, Eigen::Vector3f&)>& f) {
  MeshBuild m;
  for (int r = 0; r <= rows; ++r)
    for (int c = 0; c <= cols; ++c) {
      const float s = static_cast<float>(c) / cols, t = static_cast<float>(r) / rows;
      Eigen::Vector3f p = Eigen::Vector3f::Zero(), n = Eigen::Vector3f::UnitY();
      f(s, t, p, n);
      m.positions.push_back(p);
      m.normals.push_back(n.normalized());
      m.uvs.emplace_back(s, t);
    }
  auto at = [&](int c, int r) { return static_cast<std::uint32_t>(r * (cols + 1) + c); };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      std::uint32_t a = at(c, r), b = at(c + 1, r), d = at(c, r + 1), e = at(c + 1, r + 1);
      const Eigen::Vector3f tri_n =
          (m.positions[b] - m.positions[a]).cross(m.positions[e] - m.positions[a]);
      const Eigen::Vector3f vn = m.normals[a] + m.normals[b] + m.normals[e];
      if (tri_n.dot(vn) >= 0)
        m.indices.insert(m.indices.end(), {a, b, e, a, e, d});
      else
        m.indices.insert(m.indices.end(), {a, e, b, a, d, e});
    }
  return m;
}

}  // namespace

MeshBuild grid(const Eigen::Vector3f& origin, const Eigen::Vector3f& u, const Eigen::Vector3f& v,
               int nu, int nv, float uv_metres) {
  const Eigen::Vector3f n = u.cross(v).normalized();
  MeshBuild m = lattice(nu, nv, [&](float s, float t, Eigen::Vector3f& p, Eigen::Vector3f& nn) {
    p = origin + s * u + t * v;
    nn = n;
  });
  for (std::size_t i = 0; i < m.uvs.size(); ++i)
    m.uvs[i] = Eigen::Vector2f(m.uvs[i].x() * u.norm(), m.uvs[i].y() * v.norm()) / uv_metres;
  return m;
}

MeshBuild box(const Eigen::Vector3f& size) {
  const Eigen::Vector3f h = size / 2;
  MeshBuild m;
  // Six faces: (origin corner, u, v) with u x v pointing out.
  const Eigen::Vector3f X = Eigen::Vector3f::UnitX() * size.x(), Y = Eigen::Vector3f::UnitY() * size.y(),
                        Z = Eigen::Vector3f::UnitZ() * size.z();
  const float uvm = std::max({size.x(), size.y(), size.z()});
  m.append(grid(Eigen::Vector3f(-h.x(), -h.y(), h.z()), X, Y, 1, 1, uvm));             // +z
  m.append(grid(Eigen::Vector3f(h.x(), -h.y(), -h.z()), -X, Y, 1, 1, uvm));            // -z
  m.append(grid(Eigen::Vector3f(h.x(), -h.y(), h.z()), -Z, Y, 1, 1, uvm));             // +x
  m.append(grid(Eigen::Vector3f(-h.x(), -h.y(), -h.z()), Z, Y, 1, 1, uvm));            // -x
  m.append(grid(Eigen::Vector3f(-h.x(), h.y(), h.z()), X, -Z, 1, 1, uvm));             // +y
  m.append(grid(Eigen::Vector3f(-h.x(), -h.y(), -h.z()), X, Z, 1, 1, uvm));            // -y
  return m;
}

MeshBuild uv_sphere(float radius, int slices, int stacks) {
  return lattice(slices, stacks, [&](float s, float t, Eigen::Vector3f& p, Eigen::Vector3f& n) {
    const float phi = 2 * kPi * s, theta = kPi * t;
    n = Eigen::Vector3f(std::sin(theta) * std::cos(phi), -std::cos(theta), std::sin(theta) * std::sin(phi));
    p = radius * n;
    if (n.norm() < 1e-6f) n = Eigen::Vector3f(0, t < 0.5f ? -1.0f : 1.0f, 0);
  });
}

MeshBuild torus(float major, float minor, int slices, int sides) {
  return lattice(slices, sides, [&](float s, float t, Eigen::Vector3f& p, Eigen::Vector3f& n) {
    const float a = 2 * kPi * s, b = 2 * kPi * t;
    const Eigen::Vector3f radial(std::cos(a), 0, std::sin(a));
    n = std::cos(b) * radial + std::sin(b) * Eigen::Vector3f::UnitY();
    p = major * radial + minor * n;
  });
}

MeshBuild lathe(const std::function<Eigen::Vector2f(float)>& profile, int slices, int rings) {
  return lattice(slices, rings, [&](float s, float t, Eigen::Vector3f& p, Eigen::Vector3f& n) {
    const float a = 2 * kPi * s;
    const Eigen::Vector2f q = profile(t);
    const float dt = 1e-3f;
    const Eigen::Vector2f d = profile(std::min(t + dt, 1.0f)) - profile(std::max(t - dt, 0.0f));
    // Profile tangent (dr, dy) -> outward normal (dy, -dr) in the (radial, y) plane.
    const Eigen::Vector3f radial(std::cos(a), 0, std::sin(a));
    n = d.y() * radial - d.x() * Eigen::Vector3f::UnitY();
    if (n.norm() < 1e-9f) n = radial;
    p = q.x() * radial + Eigen::Vector3f(0, q.y(), 0);
  });
}

MeshBuild torus_knot(float scale, float radius, int pk, int qk, int segments, int sides) {
  auto curve = [&](float u) -> Eigen::Vector3f {
    const float r = std::cos(qk * u) + 2;
    return Eigen::Vector3f(r * std::cos(pk * u), -std::sin(qk * u), r * std::sin(pk * u)) * scale;
  };
  return lattice(segments, sides, [&](float s, float t, Eigen::Vector3f& p, Eigen::Vector3f& n) {
    const float u = 2 * kPi * s, v = 2 * kPi * t;
    const Eigen::Vector3f c = curve(u);
    const Eigen::Vector3f tangent = (curve(u + 1e-3f) - curve(u - 1e-3f)).normalized();
    Eigen::Vector3f side = tangent.cross(Eigen::Vector3f::UnitY());
    if (side.norm() < 1e-4f) side = tangent.cross(Eigen::Vector3f::UnitX());
    side.normalize();
    const Eigen::Vector3f up = side.cross(tangent);
    n = std::cos(v) * side + std::sin(v) * up;
    p = c + radius * n;
  });
}

}  // namespace studio::scene_tools

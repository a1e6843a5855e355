#pragma once
// Closed test meshes for the projector's mask tests (header-only): a UV sphere in any rotation, a
// watertight box, their union, and whether one mesh covers another (every vertex and face
// centre of the other inside it by winding number, computed independently of the library).
// Used by projector/mask_test.cc and velocity_field_test.cc.

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>

#include "projector/actor_mesh.h"

namespace studio::projector::testing {

// UV sphere, rotated by `rotation` so that two frames never share a tessellation.
inline ActorMesh sphere(const Eigen::Vector3d& centre, double radius,
                        const Eigen::Matrix3d& rotation, int rings = 24, int segments = 48) {
  ActorMesh m;
  m.vertices.push_back((centre + rotation * Eigen::Vector3d(0, 0, radius)).cast<float>());
  for (int i = 1; i < rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      m.vertices.push_back((centre + rotation * (radius * d)).cast<float>());
    }
  }
  m.vertices.push_back((centre + rotation * Eigen::Vector3d(0, 0, -radius)).cast<float>());
  const uint32_t south = static_cast<uint32_t>(m.vertices.size() - 1);
  auto at = [&](int ring, int j) {
    return static_cast<uint32_t>(1 + (ring - 1) * segments + (j % segments));
  };
  for (int j = 0; j < segments; ++j) m.triangles.push_back({0, at(1, j), at(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j)
    m.triangles.push_back({at(rings - 1, j), south, at(rings - 1, j + 1)});
  return m;
}

// Axis-aligned box with n cells per edge, vertices shared along edges (watertight), outward faces.
inline ActorMesh box(const Eigen::Vector3d& centre, const Eigen::Vector3d& half, int n) {
  ActorMesh m;
  std::map<std::array<long, 3>, uint32_t> index;
  auto vertex = [&](const Eigen::Vector3d& p) {
    const std::array<long, 3> key = {std::lround(p.x() * 1e6), std::lround(p.y() * 1e6),
                                     std::lround(p.z() * 1e6)};
    auto [it, inserted] = index.emplace(key, static_cast<uint32_t>(m.vertices.size()));
    if (inserted) m.vertices.push_back(p.cast<float>());
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      auto point = [&](int i, int j) -> Eigen::Vector3d {
        Eigen::Vector3d p;
        p(axis) = side * half(axis);
        p(u) = -half(u) + 2 * half(u) * i / n;
        p(v) = -half(v) + 2 * half(v) * j / n;
        return centre + p;
      };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const uint32_t a = vertex(point(i, j)), b = vertex(point(i + 1, j)),
                         c = vertex(point(i + 1, j + 1)), d = vertex(point(i, j + 1));
          if (side > 0) {
            m.triangles.push_back({a, b, c});
            m.triangles.push_back({a, c, d});
          } else {
            m.triangles.push_back({a, c, b});
            m.triangles.push_back({a, d, c});
          }
        }
    }
  return m;
}

inline ActorMesh merge(const ActorMesh& a, const ActorMesh& b) {
  ActorMesh m = a;
  const uint32_t offset = static_cast<uint32_t>(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return m;
}

// Winding number of a closed, outward-oriented mesh around p (1 inside, 0 outside).
inline double winding(const ActorMesh& m, const Eigen::Vector3d& p) {
  double total = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>() - p,
                          b = m.vertices[t[1]].cast<double>() - p,
                          c = m.vertices[t[2]].cast<double>() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    total += 2 * std::atan2(a.dot(b.cross(c)),
                            la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return total / (4 * M_PI);
}

// Largest distance by which `truth` sticks out of `cover` (0 when covered): the points of truth
// (vertices and face centres) outside cover, measured to cover's nearest vertex.
struct Coverage {
  int outside = 0;
  int points = 0;
};
inline Coverage coverage(const ActorMesh& cover, const ActorMesh& truth) {
  Coverage c;
  auto check = [&](const Eigen::Vector3d& p) {
    ++c.points;
    if (winding(cover, p) < 0.5) ++c.outside;
  };
  for (const auto& v : truth.vertices) check(v.cast<double>());
  for (const auto& t : truth.triangles)
    check((truth.vertices[t[0]] + truth.vertices[t[1]] + truth.vertices[t[2]]).cast<double>() / 3);
  return c;
}

inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

}  // namespace studio::projector::testing

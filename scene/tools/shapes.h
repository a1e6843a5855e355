#pragma once
// Procedural triangle meshes for the demo scene (counter-clockwise seen from outside, unit
// normals, texture coordinates).

#include <functional>

#include "glb_writer.h"

namespace studio::scene_tools {

// A flat grid from `origin` spanning `u` and `v` (normal = u x v), nu x nv cells, texture
// coordinates = metres / uv_metres.
MeshBuild grid(const Eigen::Vector3f& origin, const Eigen::Vector3f& u, const Eigen::Vector3f& v,
               int nu, int nv, float uv_metres);
MeshBuild box(const Eigen::Vector3f& size);  // centred at the origin
MeshBuild uv_sphere(float radius, int slices, int stacks);
MeshBuild torus(float major, float minor, int slices, int sides);  // in the xz-plane
// A surface of revolution about y: profile(s) = (radius, y) for s in [0, 1].
MeshBuild lathe(const std::function<Eigen::Vector2f(float)>& profile, int slices, int rings);
// A tube of `radius` around the (p, q) torus knot of size `scale`.
MeshBuild torus_knot(float scale, float radius, int p, int q, int segments, int sides);

}  // namespace studio::scene_tools

#pragma once
// A shape prior on the hull mesh before it is textured, as an analysis aid for
// preview_error_sources_test (issue 16, "quality against truth"; a direction measured
// and left out of the node): Laplacian steps x += lambda (mean of the neighbours - x) with the
// rim vertices anchored, as the offline surface stage does (docs/offline.md).
//
// Why it was tried: the visual hull touches the true surface only on the contour generators
// (the rims) of the cameras that carved it and lies outside it elsewhere; between two cameras'
// rims its surface is the ridge where their silhouette cones meet, which a view between those
// cameras sees as its contour, drawn over the backing (the hull's excess). Smoothing with the
// rims fixed pulls the ridges in.
// Why it is not in the node (TheShapePriorTradesExcessForUndrawnActor): it halves the excess but
// also thins the limbs inside their silhouettes (rim anchors are sparse on the hull's facets), and
// against the held-out camera an undrawn actor pixel costs ~5x an excess one.
//
// Rim vertex of camera c: the vertex projects within a pixel of c's silhouette contour (its 3x3
// neighbourhood holds both actor and backing by the chroma key) and c sees it grazing:
// |cos(normal, ray to c)| < rim_cos (normals averaged over the one-ring).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "scene/actor_mesh.h"

namespace studio::preview::held_out {

struct ShapePriorOptions {
  int steps = 0;  // 0: off
  float lambda = 0.5f;
  float rim_cos = 0.08f;
  float key_margin = 0.2f;  // the chroma key (actor_texturer.h): backing is blue above red and
                            // green by this share of full scale
};

// A camera and its RGB8 image of the mesh's frame (width*height*3 bytes, top row first).
struct KeyedView {
  const Camera* camera = nullptr;
  const uint8_t* rgb = nullptr;
};

// Smooths `mesh` in place (normals recomputed); returns the number of anchored vertices.
inline std::size_t apply_shape_prior(scene::ActorMesh& mesh, const std::vector<KeyedView>& views,
                                     const ShapePriorOptions& o) {
  const std::size_t nv = mesh.vertices.size();
  if (o.steps <= 0 || nv == 0) return 0;
  std::vector<std::vector<uint32_t>> adjacent(nv);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      for (auto [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
        auto& list = adjacent[from];
        if (std::find(list.begin(), list.end(), to) == list.end()) list.push_back(to);
      }
    }
  if (mesh.normals.size() != nv) mesh.compute_normals();
  std::vector<Eigen::Vector3f> normals(nv);
  for (std::size_t n = 0; n < nv; ++n) {
    Eigen::Vector3f s = mesh.normals[n];
    for (const uint32_t j : adjacent[n]) s += mesh.normals[j];
    normals[n] = s.norm() > 0 ? Eigen::Vector3f(s.normalized()) : s;
  }
  const int m = int(o.key_margin * 255.0f + 0.5f);
  auto actor = [m](const uint8_t* rgb, int width, int x, int y) {
    const uint8_t* p = rgb + 3 * (std::size_t(y) * width + x);
    return !(p[2] > p[0] + m && p[2] > p[1] + m);
  };
  std::vector<uint8_t> anchored(nv, 0);
  for (const KeyedView& v : views) {
    if (!v.camera || !v.rgb) continue;
    const Camera& cam = *v.camera;
    const Eigen::Vector3d centre = cam.centre_in_world();
    for (std::size_t n = 0; n < nv; ++n) {
      if (anchored[n]) continue;
      const Eigen::Vector3d x = mesh.vertices[n].cast<double>();
      if (std::abs(normals[n].cast<double>().dot((centre - x).normalized())) > o.rim_cos) continue;
      Eigen::Vector2d p;
      if (!cam.project(x, &p)) continue;
      const int px = int(std::lround(p.x())), py = int(std::lround(p.y()));
      if (px < 1 || py < 1 || px + 1 >= cam.width || py + 1 >= cam.height) continue;
      int inside = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside += actor(v.rgb, cam.width, px + dx, py + dy);
      if (inside > 0 && inside < 9) anchored[n] = 1;
    }
  }
  std::vector<Eigen::Vector3f> moved(nv);
  for (int step = 0; step < o.steps; ++step) {
    for (std::size_t n = 0; n < nv; ++n) {
      moved[n] = mesh.vertices[n];
      if (anchored[n] || adjacent[n].empty()) continue;
      Eigen::Vector3f s = Eigen::Vector3f::Zero();
      for (const uint32_t j : adjacent[n]) s += mesh.vertices[j];
      moved[n] += o.lambda * (s / float(adjacent[n].size()) - mesh.vertices[n]);
    }
    mesh.vertices.swap(moved);
  }
  mesh.compute_normals();
  return std::size_t(std::count(anchored.begin(), anchored.end(), 1));
}

}  // namespace studio::preview::held_out

#pragma once
// The offline tests' software rasteriser (header-only, test aid): z-buffered, perspective-correct
// scan conversion of a mesh in a camera, pixel centres at integer coordinates. For every pixel a
// triangle covers nearer than what the pixel holds so far, `fragment(x, y, t, w0, w1, w2, ws)` is
// called, t the triangle and w_i = l_i / z_i its perspective weights (l_i the screen barycentrics,
// z_i the vertices' depths), ws their sum: an attribute a interpolates as sum w_i a_i / ws. A
// nearer triangle later calls again for the same pixel, overwriting what the first wrote.
// Triangles with a vertex the camera does not project, or of zero screen area, are skipped.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/camera.h"
#include "hull/segment_mesh.h"

namespace studio::offline::testing {

template <class Fragment>
void raster_fragments(const hull::Mesh& mesh, const Camera& camera, Fragment&& fragment) {
  const int W = camera.width, H = camera.height;
  std::vector<float> zbuf(std::size_t(W) * H, std::numeric_limits<float>::infinity());
  std::vector<Eigen::Vector2d> p(mesh.vertices.size());
  std::vector<double> z(mesh.vertices.size());
  std::vector<std::uint8_t> ok(mesh.vertices.size());
  for (std::size_t n = 0; n < mesh.vertices.size(); ++n) {
    const Eigen::Vector3d x = mesh.vertices[n].cast<double>();
    z[n] = (camera.cam_from_world * x).z();
    ok[n] = camera.project(x, &p[n]);
  }
  for (const auto& t : mesh.triangles) {
    if (!ok[t[0]] || !ok[t[1]] || !ok[t[2]]) continue;
    const Eigen::Vector2d a = p[t[0]], b = p[t[1]], c = p[t[2]];
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(area) < 1e-12) continue;
    const int x0 = std::max(0, int(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(W - 1, int(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, int(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(H - 1, int(std::floor(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d q(x, y);
        const double l0 = ((c - b).x() * (q - b).y() - (c - b).y() * (q - b).x()) / area;
        const double l1 = ((a - c).x() * (q - c).y() - (a - c).y() * (q - c).x()) / area;
        const double l2 = 1 - l0 - l1;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        const double w0 = l0 / z[t[0]], w1 = l1 / z[t[1]], w2 = l2 / z[t[2]], ws = w0 + w1 + w2;
        const float depth = float(1 / ws);
        float& zb = zbuf[std::size_t(y) * W + x];
        if (depth >= zb) continue;
        zb = depth;
        fragment(x, y, t, w0, w1, w2, ws);
      }
  }
}

}  // namespace studio::offline::testing

#include "testing/raster.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace studio::hull::testing {

Mask rasterise(const Mesh& mesh, const Camera& camera) {
  Mask out(camera.width, camera.height, 0);
  std::vector<Eigen::Vector2d> px(mesh.vertices.size());
  std::vector<uint8_t> ok(mesh.vertices.size());
  for (std::size_t k = 0; k < px.size(); ++k) {
    ok[k] = camera.project(mesh.vertices[k].cast<double>(), &px[k]);
  }
  for (const auto& t : mesh.triangles) {
    if (!ok[t[0]] || !ok[t[1]] || !ok[t[2]]) continue;
    const Eigen::Vector2d& p0 = px[t[0]];
    const Eigen::Vector2d& p1 = px[t[1]];
    const Eigen::Vector2d& p2 = px[t[2]];
    const double area = (p1 - p0).x() * (p2 - p0).y() - (p1 - p0).y() * (p2 - p0).x();
    if (area == 0) continue;
    const double s = area > 0 ? 1 : -1;
    // Edge half-planes e(x, y) = a x + b y + c >= 0 inside.
    struct Edge {
      double a, b, c;
    } e[3];
    const Eigen::Vector2d* p[3] = {&p0, &p1, &p2};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d& q0 = *p[k];
      const Eigen::Vector2d& q1 = *p[(k + 1) % 3];
      e[k].a = -s * (q1.y() - q0.y());
      e[k].b = s * (q1.x() - q0.x());
      e[k].c = -(e[k].a * q0.x() + e[k].b * q0.y());
    }
    const double ymin = std::min({p0.y(), p1.y(), p2.y()}),
                 ymax = std::max({p0.y(), p1.y(), p2.y()});
    const double xmin = std::min({p0.x(), p1.x(), p2.x()}),
                 xmax = std::max({p0.x(), p1.x(), p2.x()});
    const int y0 = std::max(0, int(std::ceil(ymin))),
              y1 = std::min(camera.height - 1, int(std::floor(ymax)));
    for (int y = y0; y <= y1; ++y) {
      double lo = xmin, hi = xmax;
      for (const Edge& g : e) {
        const double r = -(g.b * y + g.c);  // need a x >= r
        if (g.a > 0) {
          lo = std::max(lo, r / g.a);
        } else if (g.a < 0) {
          hi = std::min(hi, r / g.a);
        } else if (r > 0) {
          lo = 1, hi = 0;
        }
      }
      const int x0 = std::max(0, int(std::ceil(lo))),
                x1 = std::min(camera.width - 1, int(std::floor(hi)));
      uint8_t* row = &out(0, y);
      for (int x = x0; x <= x1; ++x) row[x] = 255;
    }
  }
  return out;
}

}  // namespace studio::hull::testing

#pragma once
// The screen a projector lights: a rectangle of retro-reflective cloth in the studio frame, given
// by its four corners in the rig's order lower-left, lower-right, upper-right, upper-left as seen
// from the front (core/rig.h Projector::screen, DESIGN §4).
//
// Screen basis (Kooima, "Generalized Perspective Projection", 2008): unit vectors right (vr), up
// (vu) and normal (vn = vr x vu, pointing out of the front, towards the viewer). The basis is
// fitted to all four corners: right is the mean of the lower and upper edges, up the mean of the
// left and right edges made orthogonal to right; the fitted rectangle keeps the corners' centroid.
// Its corners must lie within `corner_tolerance_m` of the given ones, so a measured screen may be
// off by a few millimetres but a trapezoid, a fold or a wrong corner order is refused.
//
// Screen coordinates: (s, t) in metres from the fitted lower-left corner, s along vr, t along vu;
// the rectangle is [0, width] x [0, height]. Texture coordinates of the screen are (s / width,
// t / height): (0, 0) at the lower-left corner, (1, 1) at the upper-right (OpenGL's convention for
// a texture rendered by the eye's off-axis pass, whose NDC (-1, -1) is the lower-left corner).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "core/error.h"

namespace studio::projector {

struct ScreenOptions {
  // Largest distance between a given corner and the fitted rectangle's corner (metres).
  double corner_tolerance_m = 0.01;
  // Smallest accepted edge length (metres): shorter edges are "collinear/degenerate corners".
  double min_edge_m = 0.01;
  Expected<void> validate() const;
};

struct Screen {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // fitted lower-left corner, studio frame
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();   // vr
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();      // vu
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // vn = vr x vu, out of the front
  double width = 1;                                   // metres along vr
  double height = 1;                                  // metres along vu

  // Fits and checks the rectangle (see above). Errors, one line each: non-finite corner,
  // degenerate (coincident or collinear) corners, corners further than the tolerance from a
  // rectangle (non-planar, non-rectangular, or given in the wrong order).
  static Expected<Screen> from_corners(const std::array<Eigen::Vector3d, 4>& corners,
                                       const ScreenOptions& options = {});

  // The fitted corners, lower-left, lower-right, upper-right, upper-left.
  std::array<Eigen::Vector3d, 4> corners() const;
  // World point of screen coordinates (s, t).
  Eigen::Vector3d point(const Eigen::Vector2d& st) const {
    return origin + st.x() * right + st.y() * up;
  }
  // Screen coordinates of the orthogonal projection of x onto the screen plane.
  Eigen::Vector2d coordinates(const Eigen::Vector3d& x) const {
    return {(x - origin).dot(right), (x - origin).dot(up)};
  }
  // Distance of x from the screen plane, positive in front (on the normal's side).
  double signed_distance(const Eigen::Vector3d& x) const { return (x - origin).dot(normal); }
  // Texture coordinates (s / width, t / height) <-> screen coordinates.
  Eigen::Vector2d texture_from_screen(const Eigen::Vector2d& st) const {
    return {st.x() / width, st.y() / height};
  }
  Eigen::Vector2d screen_from_texture(const Eigen::Vector2d& uv) const {
    return {uv.x() * width, uv.y() * height};
  }
};

}  // namespace studio::projector

#pragma once
// The generalised off-axis perspective projection (Kooima, "Generalized Perspective Projection",
// 2008; the paper's view-dependent rendering, TCSVT 2004 §V-C): the view of the virtual scene from
// the actor's eye through the screen rectangle, as if the screen were a window.
//
// With the screen basis vr, vu, vn and corners pa (lower-left), pb (lower-right), pc (upper-left)
// (projector/screen.h) and the eye pe:
//   va = pa - pe, vb = pb - pe, vc = pc - pe,  d = -va . vn  (eye-to-plane distance, > 0 in front)
//   l = (vr . va) n / d,  r = (vr . vb) n / d,  b = (vu . va) n / d,  t = (vu . vc) n / d
//   clip_from_world = frustum(l, r, b, t, n, f) * [vr vu vn]^T * translate(-pe)
// where frustum() is glFrustum's matrix. The "view" frame has x = vr, y = vu, z = vn and the eye
// at its origin; the screen is the plane z = -d; near and far are planes parallel to the screen at
// distances n and f from the eye. The screen rectangle maps exactly onto NDC [-1, 1]^2 (x along
// vr, y along vu), so NDC (x, y) <-> screen coordinates (s, t) = ((x + 1) w / 2, (y + 1) h / 2).

#include <Eigen/Core>

#include "core/error.h"
#include "projector/screen.h"

namespace studio::projector {

struct OffAxisOptions {
  double near_m = 0.05;  // near plane distance from the eye, parallel to the screen
  double far_m = 100;    // far plane distance
  // The eye must be at least this far in front of the screen plane (an eye on or behind the
  // plane sees the back of the cloth: refused).
  double min_eye_distance_m = 0.05;
  Expected<void> validate() const;
};

struct OffAxisView {
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  double distance = 0;  // d: eye to screen plane, metres
  double left = 0, right = 0, bottom = 0, top = 0, near = 0,
         far = 0;  // the frustum at the near plane
  Eigen::Matrix4d view_from_world = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d clip_from_view = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d clip_from_world = Eigen::Matrix4d::Identity();
};

// Errors: invalid options; a non-finite eye; an eye behind, on, or closer than
// min_eye_distance_m to the screen plane.
Expected<OffAxisView> off_axis_view(const Screen& screen, const Eigen::Vector3d& eye,
                                    const OffAxisOptions& options = {});

// glFrustum's matrix (OpenGL clip space: NDC z in [-1, 1], -1 at the near plane).
Eigen::Matrix4d frustum(double left, double right, double bottom, double top, double near,
                        double far);

}  // namespace studio::projector

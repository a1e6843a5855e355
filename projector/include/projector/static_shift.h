#pragma once
// How far the static scene moves in the projector image when the eye moves (issue 15: render the
// scene only when it changes). The projector frame reuses the static part of the scene rendered
// from an earlier eye e0 (colour + depth) while every static point it shows lands within
// `max_error_px` projector pixels of where a full render from the current eye e1 puts it.
//
// Derivation (screen basis vr, vu, vn of projector/screen.h; heights h along vn from the screen
// plane, tangential coordinates x_t in the plane). A scene point P at height h_p seen from the eye
// e at height h_e > h_p appears on the screen where the ray e -> P meets the plane:
//   X(e) = e + h_e / (h_e - h_p) (P - e)  =  (h_e P - h_p e) / (h_e - h_p)       (tangential part)
// Its derivative with respect to the eye, for a move d = d_t + d_n vn:
//   dX = -h_p / (h_e - h_p) d_t  -  h_p (P_t - e_t) / (h_e - h_p)^2 d_n
// so, with tan(theta) = |P_t - e_t| / (h_e - h_p) = |X_t - e_t| / h_e (the ray's slope, the same
// at P and at X; at most the largest corner slope, since X lies in the rectangle),
//   |dX| <= f(h_p, h_e) (|d_t| + tan(theta_max) |d_n|),   f(h, h_e) = |h| / (h_e - h).      (1)
// A point on the screen (h = 0) does not move; one far behind it (h -> -inf) moves with the eye
// (f -> 1); one in front of it moves more (f grows to (h_e - n) / n at the eye's near plane n).
// Over the static points shown, heights lie in [h_lo, h_hi] (h_hi <= h_e - n): f is largest at one
// end of that range (it grows with |h| on either side of 0). Along the move e(l) = e0 + l d the
// eye height is linear in l: f decreases with h_e at a fixed h, and when h_hi is capped by the
// near plane, f at the cap (h_e - n) / n grows with h_e; the bound takes f at both ends of the
// move and at h_e = h_hi + n when that lies between (the peak of the capped form), and the
// largest corner slope over both ends (|c_t - e_t| is convex along the move). Integrating (1)
// along the move bounds the screen displacement in metres; the homography pixel_from_screen maps
// it to projector pixels with at most its largest local scale over the rectangle, s_max = max
// sigma_max(J(s, t)) (sampled on a 65 x 65 grid over the rectangle, plus 1 % for the gaps):
//   shift_px(e0, e1) <= s_max * f_max * (|d_t| + tan(theta_max) |d_n|).                    (2)
// For an isotropic bound on |d| (Cauchy-Schwarz): |d_t| + tan |d_n| <= |d| sqrt(1 + tan^2).
//
// What the heights cover: the caller passes the range of the static points the cached frame shows
// (its depth buffer, projector_render::FrameRenderer). A static point hidden at e0 or just outside
// the rectangle shows after the move only as a sliver along an occluding edge or the rectangle's
// border (disocclusion), as wide as the occluder's own bounded shift — not counted here.
// Lighting that depends on the eye (specular) is not a displacement: the renderer's tests bound it
// by PSNR.

#include <Eigen/Core>

#include "core/error.h"
#include "projector/projector_view.h"

namespace studio::projector {

struct SceneCacheOptions {
  bool enabled = true;
  // Largest displacement of a static point between the cached and a fully rendered frame,
  // projector pixels.
  double max_error_px = 0.5;
  // A scene node that changes is drawn every frame (with the animated ones) until it has not
  // changed for this long; then it joins the cached static part (seconds; projector node).
  double settle_s = 1.0;
  // A layer drawn for a moving eye also serves up to this many following frames, however far
  // the eye moved, so the static scene is redrawn at most every hold_frames + 1 frames (0: the
  // bound above alone decides). The static scene then lags the eye by up to hold_frames frames
  // (FrameInfo::shift_px bounds each held frame's error); the moving nodes and the masks are
  // drawn every frame from the current eye and prediction, so the actor's blackout is
  // unaffected. For projector PCs without a GPU, where drawing the static scene costs most of a
  // frame (BENCHMARKS.md, projector).
  int hold_frames = 0;
  Expected<void> validate() const;
};

// The range of heights above the screen plane (metres, + in front) of the static points shown.
struct HeightRange {
  double lo = 0, hi = 0;
};

class StaticShiftBound {
 public:
  // Errors: invalid off-axis options.
  static Expected<StaticShiftBound> create(const ProjectorView& view,
                                           const OffAxisOptions& off_axis = {});

  // Upper bound (2) on the displacement in projector pixels of any static point with height in
  // `heights`, between a frame rendered from eye e0 and one from e1 (both in front of the
  // screen). +inf when either eye is not in front of the screen by more than the near plane.
  double shift_px(const HeightRange& heights, const Eigen::Vector3d& e0,
                  const Eigen::Vector3d& e1) const;
  // The largest eye move (metres, any direction) from `eye` under which shift_px stays within
  // `max_px` (the isotropic form of (2) at this eye, first order in the move: a report figure,
  // the cache decides with shift_px).
  double allowed_move_m(const HeightRange& heights, const Eigen::Vector3d& eye,
                        double max_px) const;
  // s_max: projector pixels per metre on the screen, the largest over the rectangle.
  double pixels_per_metre() const { return scale_; }

 private:
  Screen screen_;
  double near_ = 0.05;
  double scale_ = 0;
};

}  // namespace studio::projector

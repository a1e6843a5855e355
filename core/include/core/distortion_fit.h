#pragma once
// Explicit conversion of a camera with OpenCV distortion to the paper's radial model (TCSVT 2004
// §IV-A), never a silent rename of coefficients.
//
// Both models map ideal (undistorted) normalised coordinates p to observed (distorted) ones
// (core/camera.h):
//   the paper's  d(p) = p (1 + rd3 r'^2 + rd5 r'^4)       i.e. r = r' + rd3 r'^3 + rd5 r'^5
//   OpenCV's     d(p) = p (1 + k1 r'^2 + k2 r'^4 + k3 r'^6) + tangential(p1, p2)
// so a radial-only OpenCV camera (p1 = p2 = k3 = 0) is exactly rd3 = k1, rd5 = k2. Otherwise the
// conversion is a least-squares fit: sample a grid of observed pixels covering the image, map
// each back to its ideal point p with OpenCV's model (Newton, core/camera.h undistort), and
// choose (rd3, rd5) minimising the sum over samples of |K d_paper(p) - K d_opencv(p)|^2 — the
// squared pixel distance at which the two models image the same ray. The problem is linear in
// (rd3, rd5): per sample, two equations (u and v)
//   (fx x + s y) r'^2 rd3 + (fx x + s y) r'^4 rd5 = fx (x_cv - x) + s (y_cv - y)
//    fy y        r'^2 rd3 +  fy y        r'^4 rd5 = fy (y_cv - y)
// solved by QR. The residual (max and RMS over the samples, in pixels) is reported; the
// conversion is refused with a one-line error when the max exceeds the tolerance (strong
// tangential terms or k3 that the paper's model cannot represent).

#include "core/camera.h"
#include "core/error.h"

namespace studio {

struct PaperModelOptions {
  double max_residual_px = 0.5;  // refuse when any sample moves by more than this (pixels)
  int grid = 41;                 // grid x grid samples over the image (corners included)
  Expected<void> validate() const;
};

struct PaperModelFit {
  Camera camera;               // distortion: Model::radial (or none when the input had none)
  double max_residual_px = 0;  // over the samples
  double rms_residual_px = 0;
  int samples = 0;             // samples used (0 when no fit was needed)
  bool fitted = false;         // true when the input had OpenCV distortion
};

// The camera with the paper's distortion model. Cameras without distortion or with the paper's
// model are returned unchanged (residual 0, fitted = false). Fails (message naming the camera,
// the coefficients, the residual and the tolerance) when the fit's max residual exceeds
// options.max_residual_px, or when the camera's size or OpenCV model is unusable (fewer than
// half of the samples map back to an ideal point).
Expected<PaperModelFit> to_paper_model(const Camera& camera, const PaperModelOptions& options = {});

}  // namespace studio

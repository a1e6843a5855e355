#include "core/distortion_fit.h"

#include <Eigen/QR>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace studio {
namespace {

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

// Observed pixel of ideal normalised point p under distortion d.
Eigen::Vector2d pixel(const Intrinsics& k, const Distortion& d, const Eigen::Vector2d& p) {
  const Eigen::Vector2d n = distort(d, p);
  return {k.fx * n.x() + k.skew * n.y() + k.cx, k.fy * n.y() + k.cy};
}

}  // namespace

Expected<void> PaperModelOptions::validate() const {
  if (!(max_residual_px > 0) || !std::isfinite(max_residual_px))
    return fail("max_residual_px must be > 0 pixels");
  if (grid < 3 || grid > 1000) return fail("grid must be in [3, 1000]");
  return {};
}

Expected<PaperModelFit> to_paper_model(const Camera& camera, const PaperModelOptions& options) {
  if (auto ok = options.validate(); !ok) return fail("to_paper_model: " + ok.error().message);
  PaperModelFit out;
  out.camera = camera;
  const Distortion& d = camera.distortion;
  if (d.model != Distortion::Model::opencv) return out;
  const std::string who = "camera " + camera.id;
  if (camera.width <= 0 || camera.height <= 0)
    return fail(who + ": OpenCV distortion: image size needed to fit the paper's model");
  const Intrinsics& k = camera.intrinsics;
  if (!(k.fx > 0) || !(k.fy > 0)) return fail(who + ": focal length <= 0");

  // Ideal points of a grid of observed pixels over the whole image (pixel centres of the border).
  std::vector<Eigen::Vector2d> ideal;
  const int n = options.grid;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d observed_px((camera.width - 1) * double(i) / (n - 1),
                                        (camera.height - 1) * double(j) / (n - 1));
      const double y = (observed_px.y() - k.cy) / k.fy;
      const double x = (observed_px.x() - k.cx - k.skew * y) / k.fx;
      const Eigen::Vector2d p = undistort(d, {x, y});
      // Keep only points where Newton converged (the model may fold beyond the image's corners).
      if (p.allFinite() && (pixel(k, d, p) - observed_px).norm() < 1e-6) ideal.push_back(p);
    }
  }
  if (ideal.size() * 2 < std::size_t(n) * n)
    return fail(who + ": OpenCV distortion does not map the image back to ideal points "
                      "(the model folds inside the image); recalibrate");

  Eigen::MatrixXd A(2 * ideal.size(), 2);
  Eigen::VectorXd b(2 * ideal.size());
  for (std::size_t s = 0; s < ideal.size(); ++s) {
    const Eigen::Vector2d& p = ideal[s];
    const double r2 = p.squaredNorm();
    const Eigen::Vector2d cv = distort(d, p) - p;  // OpenCV's displacement (normalised)
    const double u = k.fx * p.x() + k.skew * p.y();
    const double v = k.fy * p.y();
    A.row(2 * s) << u * r2, u * r2 * r2;
    A.row(2 * s + 1) << v * r2, v * r2 * r2;
    b(2 * s) = k.fx * cv.x() + k.skew * cv.y();
    b(2 * s + 1) = k.fy * cv.y();
  }
  const Eigen::Vector2d rd = A.colPivHouseholderQr().solve(b);
  out.camera.distortion = Distortion::radial(rd.x(), rd.y());
  out.fitted = true;
  out.samples = int(ideal.size());
  double sum2 = 0;
  for (const Eigen::Vector2d& p : ideal) {
    const double e = (pixel(k, out.camera.distortion, p) - pixel(k, d, p)).norm();
    out.max_residual_px = std::max(out.max_residual_px, e);
    sum2 += e * e;
  }
  out.rms_residual_px = std::sqrt(sum2 / double(ideal.size()));
  if (!(out.max_residual_px <= options.max_residual_px)) {
    return fail(who + ": OpenCV distortion (k1 " + number(d.k1) + ", k2 " + number(d.k2) + ", p1 " +
                number(d.p1) + ", p2 " + number(d.p2) + ", k3 " + number(d.k3) +
                ") does not fit the paper's radial model r = r' + rd3 r'^3 + rd5 r'^5: max residual " +
                number(out.max_residual_px) + " px (RMS " + number(out.rms_residual_px) +
                " px) over the image exceeds " + number(options.max_residual_px) +
                " px (tangential p1, p2 or k3 too large); recalibrate with the paper's model");
  }
  return out;
}

}  // namespace studio

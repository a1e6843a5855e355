// Projector calibration: triangulation, screen plane, resection
// (calibrate/projector_calibration.h). Holds the projector's Ceres cost functions (the cameras'
// bundle keeps its own in bundle.cc).
#include "calibrate/projector_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <memory>

#include "calibrate/text.h"

namespace studio::calibrate {
namespace {

using Poly = DistortionPolynomial;  // core/camera.h
Poly poly(const Distortion& d) { return polynomial(d); }

// A fixed, calibrated camera observing a free world point (triangulation refinement).
struct PointCost {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  Intrinsics k;
  Poly d;
  Eigen::Vector2d observed;
  double weight = 1;  // 1 / sigma
  template <typename T>
  bool operator()(const T* x, T* residual) const {
    T c[3];
    for (int i = 0; i < 3; ++i) c[i] = R(i, 0) * x[0] + R(i, 1) * x[1] + R(i, 2) * x[2] + t(i);
    if (!(c[2] > T(1e-9))) return false;
    const T a = c[0] / c[2], b = c[1] / c[2];
    const T r2 = a * a + b * b;
    const T radial = T(1) + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
    const T xd = a * radial + 2.0 * d.p1 * a * b + d.p2 * (r2 + 2.0 * a * a);
    const T yd = b * radial + d.p1 * (r2 + 2.0 * b * b) + 2.0 * d.p2 * a * b;
    residual[0] = weight * (k.fx * xd + k.skew * yd + k.cx - observed.x());
    residual[1] = weight * (k.fy * yd + k.cy - observed.y());
    return true;
  }
};

// The projector as a camera: intrinsics [fx, fy, cx, cy, rd3, rd5], pose [angle-axis, t] of
// cam_from_world; a fixed triangulated point; the pattern's projector pixel as the observation.
enum { kFx = 0, kFy, kCx, kCy, kRd3, kRd5, kProjectorIntrinsics };
template <typename T>
bool project_projector(const T* k, const T* pose, const T* p, T* out) {
  T c[3];
  ceres::AngleAxisRotatePoint(pose, p, c);
  for (int i = 0; i < 3; ++i) c[i] += pose[3 + i];
  if (!(c[2] > T(1e-9))) return false;
  const T a = c[0] / c[2], b = c[1] / c[2];
  const T r2 = a * a + b * b;
  const T radial = T(1) + r2 * (k[kRd3] + r2 * k[kRd5]);
  out[0] = k[kFx] * radial * a + k[kCx];
  out[1] = k[kFy] * radial * b + k[kCy];
  return true;
}

// The joint solve's projector residual: the point is a parameter too.
struct JointProjectorCost {
  Eigen::Vector2d pixel;
  double weight = 1;  // 1 / sigma
  template <typename T>
  bool operator()(const T* k, const T* pose, const T* x, T* residual) const {
    T p[2];
    if (!project_projector(k, pose, x, p)) return false;
    residual[0] = weight * (p[0] - pixel.x());
    residual[1] = weight * (p[1] - pixel.y());
    return true;
  }
};

struct ResectionCost {
  Eigen::Vector3d point;
  Eigen::Vector2d pixel;
  template <typename T>
  bool operator()(const T* k, const T* pose, T* residual) const {
    const T p[3] = {T(point.x()), T(point.y()), T(point.z())};
    T c[3];
    ceres::AngleAxisRotatePoint(pose, p, c);
    for (int i = 0; i < 3; ++i) c[i] += pose[3 + i];
    if (!(c[2] > T(1e-9))) return false;
    const T a = c[0] / c[2], b = c[1] / c[2];
    const T r2 = a * a + b * b;
    const T radial = T(1) + r2 * (k[kRd3] + r2 * k[kRd5]);
    residual[0] = k[kFx] * radial * a + k[kCx] - pixel.x();
    residual[1] = k[kFy] * radial * b + k[kCy] - pixel.y();
    return true;
  }
};

Eigen::Vector2d normalised_ideal(const Camera& c, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d observed = (c.intrinsics.K().inverse() * pixel.homogeneous()).hnormalized();
  return undistort(c.distortion, observed);
}

double rms_projector(const Camera& c, const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels) {
  double sum = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d p;
    if (!c.project(points[i], &p)) return INFINITY;
    sum += (p - pixels[i]).squaredNorm();
  }
  return std::sqrt(sum / std::max<size_t>(1, points.size()));
}

}  // namespace

Expected<void> ProjectorCalibrationOptions::validate() const {
  if (id.empty()) return fail("projector calibration: empty projector id");
  if (width <= 0 || height <= 0)
    return fail(
        format("projector calibration: projector size {}x{} must be positive", width, height));
  if (!(max_triangulation_rms_px > 0))
    return fail("projector calibration: max_triangulation_rms_px must be > 0");
  if (!(plane_outlier_sigmas > 0))
    return fail("projector calibration: plane_outlier_sigmas must be > 0");
  if (!(loss_scale_px > 0)) return fail("projector calibration: loss_scale_px must be > 0");
  if (max_iterations < 1) return fail("projector calibration: max_iterations must be >= 1");
  if (screen_corners)
    for (const auto& c : *screen_corners)
      if (!c.allFinite()) return fail("projector calibration: non-finite screen corner");
  return {};
}

Expected<Eigen::Vector3d> triangulate_dlt(const std::vector<Camera>& cameras,
                                          const std::vector<PatternView>& views) {
  if (views.size() < 2) return fail("triangulate: need >= 2 views");
  Eigen::MatrixXd a(2 * views.size(), 4);
  std::vector<Eigen::Vector3d> rays;
  for (size_t i = 0; i < views.size(); ++i) {
    const PatternView& v = views[i];
    if (v.camera < 0 || v.camera >= static_cast<int>(cameras.size()))
      return fail(format("triangulate: camera index {} out of range", v.camera));
    if (!v.pixel.allFinite()) return fail("triangulate: non-finite pixel");
    const Camera& c = cameras[v.camera];
    const Eigen::Vector2d n = normalised_ideal(c, v.pixel);
    const Eigen::Matrix<double, 3, 4> P = c.cam_from_world.matrix3x4();
    a.row(2 * i) = n.x() * P.row(2) - P.row(0);
    a.row(2 * i + 1) = n.y() * P.row(2) - P.row(1);
    rays.push_back(c.cam_from_world.rotation.conjugate() * n.homogeneous().normalized());
  }
  double widest = 0;  // largest angle between two rays
  for (size_t i = 0; i < rays.size(); ++i)
    for (size_t j = i + 1; j < rays.size(); ++j)
      widest = std::max(widest, std::acos(std::clamp(rays[i].dot(rays[j]), -1.0, 1.0)));
  if (widest < 1e-3) return fail("triangulate: the rays are (nearly) parallel");
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12 * h.head<3>().norm()) return fail("triangulate: point at infinity");
  const Eigen::Vector3d x = h.hnormalized();
  for (const PatternView& v : views)
    if (!((cameras[v.camera].cam_from_world * x).z() > 0))
      return fail("triangulate: the point is behind a camera");
  return x;
}

Expected<std::pair<Eigen::Vector3d, double>> refine_point(const std::vector<Camera>& cameras,
                                                          const std::vector<PatternView>& views,
                                                          const Eigen::Vector3d& initial) {
  double x[3] = {initial.x(), initial.y(), initial.z()};
  ceres::Problem problem;
  for (const PatternView& v : views) {
    const Camera& c = cameras[v.camera];
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PointCost, 2, 3>(
                                 new PointCost{c.cam_from_world.R(), c.cam_from_world.translation,
                                               c.intrinsics, poly(c.distortion), v.pixel}),
                             nullptr, x);
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 50;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable())
    return fail("triangulate: refinement failed: " + summary.message);
  const Eigen::Vector3d out(x[0], x[1], x[2]);
  if (!out.allFinite()) return fail("triangulate: refinement diverged");
  const double rms = std::sqrt(2 * summary.final_cost / (2.0 * views.size()));
  return std::pair{out, rms};
}

Expected<Plane> fit_plane(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 3) return fail("plane: need >= 3 points");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(scatter, Eigen::ComputeFullU);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(1) > 1e-12 * std::max(1.0, s(0)))) return fail("plane: the points are collinear");
  Plane plane;
  plane.normal = svd.matrixU().col(2);
  plane.offset = plane.normal.dot(mean);
  return plane;
}

Expected<Camera> resect_dlt(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels, int width, int height) {
  if (points.size() != pixels.size() || points.size() < 6)
    return fail("resection: need >= 6 point/pixel pairs");
  // Hartley normalisation of both sides.
  Eigen::Vector3d m3 = Eigen::Vector3d::Zero();
  Eigen::Vector2d m2 = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    m3 += points[i];
    m2 += pixels[i];
  }
  m3 /= static_cast<double>(points.size());
  m2 /= static_cast<double>(points.size());
  double d3 = 0, d2 = 0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    d3 += (points[i] - m3).norm();
    d2 += (pixels[i] - m2).norm();
    scatter += (points[i] - m3) * (points[i] - m3).transpose();
  }
  d3 /= static_cast<double>(points.size());
  d2 /= static_cast<double>(points.size());
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(scatter).singularValues();
  if (!(std::sqrt(sv(2) / sv(0)) > 1e-3))
    return fail(
        "resection: all pattern points lie on one plane, which does not determine the projector's "
        "K and pose: let the pattern also fall on a second surface (the floor, another wall, or a "
        "board)");
  if (!(d2 > 0)) return fail("resection: every pixel is the same");
  const double s3 = std::sqrt(3.0) / d3, s2 = std::sqrt(2.0) / d2;
  Eigen::Matrix4d t3 = Eigen::Matrix4d::Identity();
  t3.topLeftCorner<3, 3>() *= s3;
  t3.block<3, 1>(0, 3) = -s3 * m3;
  Eigen::Matrix3d t2 = Eigen::Matrix3d::Identity();
  t2.topLeftCorner<2, 2>() *= s2;
  t2.block<2, 1>(0, 2) = -s2 * m2;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * points.size(), 12);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector4d X = t3 * points[i].homogeneous();
    const Eigen::Vector2d x = (t2 * pixels[i].homogeneous()).head<2>();
    a.block<1, 4>(2 * i, 0) = X.transpose();
    a.block<1, 4>(2 * i, 8) = -x.x() * X.transpose();
    a.block<1, 4>(2 * i + 1, 4) = X.transpose();
    a.block<1, 4>(2 * i + 1, 8) = -x.y() * X.transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd p = svd.matrixV().col(11);
  Eigen::Matrix<double, 3, 4> pn;
  pn << p(0), p(1), p(2), p(3), p(4), p(5), p(6), p(7), p(8), p(9), p(10), p(11);
  const Eigen::Matrix<double, 3, 4> P = t2.inverse() * pn * t3;
  auto camera = camera_from_projection_matrix(P, width, height);
  if (!camera) return fail("resection: " + camera.error().message);
  // The decomposition fixes the sign so that det(KR) > 0; the points must then be in front.
  int in_front = 0;
  for (const auto& x : points) in_front += (camera->cam_from_world * x).z() > 0;
  if (in_front * 2 < static_cast<int>(points.size()))
    return fail("resection: the points are behind the projector (degenerate configuration)");
  return camera;
}

void store_projector(Rig* rig, const Projector& projector) {
  if (Projector* existing = rig->find_projector(projector.camera.id)) {
    *existing = projector;
    return;
  }
  rig->projectors.push_back(projector);
}

Expected<ProjectorCalibrationResult> calibrate_projector(
    const std::vector<Camera>& cameras, const std::vector<PatternFeature>& features,
    const ProjectorCalibrationOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  ProjectorCalibrationResult result;
  result.features = static_cast<int>(features.size());
  result.points.assign(features.size(), Eigen::Vector3d::Constant(NAN));

  // 1. Triangulation.
  double triangulation_sum = 0;
  int triangulation_views = 0;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<int> kept;  // feature index of points[j]
  for (size_t i = 0; i < features.size(); ++i) {
    const PatternFeature& f = features[i];
    for (const PatternView& v : f.views)
      if (v.camera < 0 || v.camera >= static_cast<int>(cameras.size()))
        return fail(format("projector calibration: feature {} names camera {} of {}", i, v.camera,
                           cameras.size()));
    if (!f.projector_pixel.allFinite())
      return fail(format("projector calibration: feature {} has a non-finite projector pixel", i));
    if (f.views.size() < 2) continue;
    auto dlt = triangulate_dlt(cameras, f.views);
    if (!dlt) continue;
    auto refined = refine_point(cameras, f.views, *dlt);
    if (!refined || refined->second > options.max_triangulation_rms_px) continue;
    result.points[i] = refined->first;
    kept.push_back(static_cast<int>(i));
    triangulation_sum += refined->second * refined->second * f.views.size();
    triangulation_views += static_cast<int>(f.views.size());
    points.push_back(refined->first);
    pixels.push_back(f.projector_pixel);
  }
  result.triangulated = static_cast<int>(points.size());
  if (points.size() < 6)
    return fail(
        format("projector calibration: only {} of {} features triangulated (need >= 6 seen "
               "by >= 2 cameras)",
               points.size(), features.size()));
  result.triangulation_rms_px = std::sqrt(triangulation_sum / triangulation_views);
  int on_screen = 0;
  for (int i : kept) on_screen += features[i].surface == options.screen_surface;
  if (on_screen < 3)
    return fail(
        format("projector calibration: only {} triangulated features on the screen surface {} "
               "(need >= 3)",
               on_screen, options.screen_surface));
  if (auto all = fit_plane(points); all) {
    double sum = 0;
    for (const auto& x : points) sum += all->distance(x) * all->distance(x);
    if (std::sqrt(sum / points.size()) < options.min_off_plane_m)
      return fail(format(
          "projector calibration: all pattern points lie on one plane (RMS {:.1f} mm off it, need "
          ">= {:.1f} mm), which does not determine the projector's K and pose: let the pattern "
          "also "
          "fall on a second surface (the floor, another wall, or a board)",
          1e3 * std::sqrt(sum / points.size()), 1e3 * options.min_off_plane_m));
  }

  // 3. Resection (before the plane: the plane's normal is oriented towards the projector).
  auto camera = resect_dlt(points, pixels, options.width, options.height);
  if (!camera) return fail("projector calibration: " + camera.error().message);
  result.dlt_rms_px = rms_projector(*camera, points, pixels);
  {
    double k[kProjectorIntrinsics] = {camera->intrinsics.fx,
                                      camera->intrinsics.fy,
                                      camera->intrinsics.cx,
                                      camera->intrinsics.cy,
                                      0,
                                      0};
    const Eigen::AngleAxisd aa(camera->cam_from_world.rotation);
    const Eigen::Vector3d r = aa.angle() * aa.axis();
    const Eigen::Vector3d& t = camera->cam_from_world.translation;
    double pose[6] = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
    ceres::Problem problem;
    for (size_t i = 0; i < points.size(); ++i) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ResectionCost, 2, kProjectorIntrinsics, 6>(
              new ResectionCost{points[i], pixels[i]}),
          new ceres::HuberLoss(options.loss_scale_px), k, pose);
    }
    if (!options.fit_radial)
      problem.SetManifold(k, new ceres::SubsetManifold(kProjectorIntrinsics, {kRd3, kRd5}));
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.max_num_iterations = options.max_iterations;
    solver.function_tolerance = 1e-12;
    solver.parameter_tolerance = 1e-12;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (!summary.IsSolutionUsable())
      return fail("projector calibration: resection refinement failed: " + summary.message);
    result.iterations = static_cast<int>(summary.iterations.size());
    if (!(k[kFx] > 0) || !(k[kFy] > 0) || !std::isfinite(k[kCx]) || !std::isfinite(k[kCy]))
      return fail("projector calibration: resection refinement diverged");
    camera->intrinsics = Intrinsics{k[kFx], k[kFy], k[kCx], k[kCy], 0};
    camera->distortion =
        options.fit_radial ? Distortion::radial(k[kRd3], k[kRd5]) : Distortion::none();
    const Eigen::Vector3d v(pose[0], pose[1], pose[2]);
    const double angle = v.norm();
    camera->cam_from_world =
        Rigid3(angle < 1e-15 ? Eigen::Quaterniond::Identity()
                             : Eigen::Quaterniond(Eigen::AngleAxisd(angle, v / angle)),
               Eigen::Vector3d(pose[3], pose[4], pose[5]));
  }
  camera->id = options.id;
  result.resection_rms_px = rms_projector(*camera, points, pixels);

  // Joint refinement: the projector is one more (exactly observed) camera of every feature, so
  // the points move with it; the cameras stay fixed (they are calibrated).
  if (options.joint) {
    double k[kProjectorIntrinsics] = {camera->intrinsics.fx,  camera->intrinsics.fy,
                                      camera->intrinsics.cx,  camera->intrinsics.cy,
                                      camera->distortion.rd3, camera->distortion.rd5};
    const Eigen::AngleAxisd aa(camera->cam_from_world.rotation);
    const Eigen::Vector3d r = aa.angle() * aa.axis();
    const Eigen::Vector3d& t = camera->cam_from_world.translation;
    double pose[6] = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
    std::vector<std::array<double, 3>> x(points.size());
    ceres::Problem problem;
    for (size_t j = 0; j < points.size(); ++j) {
      x[j] = {points[j].x(), points[j].y(), points[j].z()};
      for (const PatternView& v : features[kept[j]].views) {
        const Camera& c = cameras[v.camera];
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<PointCost, 2, 3>(
                new PointCost{c.cam_from_world.R(), c.cam_from_world.translation, c.intrinsics,
                              poly(c.distortion), v.pixel, 1 / options.camera_noise_px}),
            new ceres::HuberLoss(options.loss_scale_px / options.camera_noise_px), x[j].data());
      }
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<JointProjectorCost, 2, kProjectorIntrinsics, 6, 3>(
              new JointProjectorCost{pixels[j], 1 / options.projector_noise_px}),
          nullptr, k, pose, x[j].data());
    }
    if (!options.fit_radial)
      problem.SetManifold(k, new ceres::SubsetManifold(kProjectorIntrinsics, {kRd3, kRd5}));
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_SCHUR;
    solver.max_num_iterations = options.max_iterations;
    solver.function_tolerance = 1e-12;
    solver.parameter_tolerance = 1e-12;
    solver.num_threads = 2;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (!summary.IsSolutionUsable())
      return fail("projector calibration: joint refinement failed: " + summary.message);
    result.iterations += static_cast<int>(summary.iterations.size());
    if (!(k[kFx] > 0) || !(k[kFy] > 0) || !std::isfinite(k[kCx]) || !std::isfinite(k[kCy]))
      return fail("projector calibration: joint refinement diverged");
    camera->intrinsics = Intrinsics{k[kFx], k[kFy], k[kCx], k[kCy], 0};
    camera->distortion =
        options.fit_radial ? Distortion::radial(k[kRd3], k[kRd5]) : Distortion::none();
    const Eigen::Vector3d v(pose[0], pose[1], pose[2]);
    const double angle = v.norm();
    camera->cam_from_world =
        Rigid3(angle < 1e-15 ? Eigen::Quaterniond::Identity()
                             : Eigen::Quaterniond(Eigen::AngleAxisd(angle, v / angle)),
               Eigen::Vector3d(pose[3], pose[4], pose[5]));
    double sum = 0;
    int n = 0;
    for (size_t j = 0; j < points.size(); ++j) {
      points[j] = Eigen::Vector3d(x[j][0], x[j][1], x[j][2]);
      result.points[kept[j]] = points[j];
      for (const PatternView& v : features[kept[j]].views) {
        Eigen::Vector2d p;
        if (cameras[v.camera].project(points[j], &p)) sum += (p - v.pixel).squaredNorm();
        ++n;
      }
    }
    result.camera_rms_px = std::sqrt(sum / std::max(1, n));
  }
  result.rms_px = rms_projector(*camera, points, pixels);
  std::vector<Eigen::Vector3d> screen;
  for (size_t j = 0; j < points.size(); ++j)
    if (features[kept[j]].surface == options.screen_surface) screen.push_back(points[j]);

  // 2. Screen plane, outliers dropped and the fit repeated.
  std::vector<Eigen::Vector3d> inliers = screen;
  Expected<Plane> plane = fit_plane(inliers);
  for (int round = 0; plane && round < 5; ++round) {
    double sum = 0;
    for (const auto& p : inliers) sum += plane->distance(p) * plane->distance(p);
    const double sigma = std::sqrt(sum / inliers.size());
    std::vector<Eigen::Vector3d> kept;
    for (const auto& p : screen)
      if (std::abs(plane->distance(p)) <= std::max(options.plane_outlier_sigmas * sigma, 1e-4))
        kept.push_back(p);
    if (kept.size() == inliers.size() || kept.size() < 3) break;
    inliers = std::move(kept);
    plane = fit_plane(inliers);
  }
  if (!plane) return fail("projector calibration: screen " + plane.error().message);
  const Eigen::Vector3d centre = camera->centre_in_world();
  if (plane->distance(centre) < 0) {
    plane->normal = -plane->normal;
    plane->offset = -plane->offset;
  }
  result.screen_plane = *plane;
  result.screen_points = static_cast<int>(inliers.size());
  double sum = 0;
  for (const auto& p : inliers) sum += plane->distance(p) * plane->distance(p);
  result.plane_rms_m = std::sqrt(sum / inliers.size());

  // 4. Screen corners.
  Projector projector;
  projector.camera = *camera;
  const Eigen::Vector3d& n = plane->normal;
  if (options.screen_corners) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d& c = (*options.screen_corners)[i];
      projector.screen[i] = c - n * plane->distance(c);
    }
  } else {
    Eigen::Vector3d up = Eigen::Vector3d::UnitY() - n * n.y();
    if (up.norm() < 0.1) {  // a horizontal screen: "up" is the projector's image up (-y)
      const Eigen::Vector3d image_up =
          camera->cam_from_world.rotation.conjugate() * -Eigen::Vector3d::UnitY();
      up = image_up - n * n.dot(image_up);
    }
    up.normalize();
    const Eigen::Vector3d right = up.cross(n);
    double s0 = INFINITY, s1 = -INFINITY, t0 = INFINITY, t1 = -INFINITY;
    for (const auto& p : inliers) {
      s0 = std::min(s0, right.dot(p));
      s1 = std::max(s1, right.dot(p));
      t0 = std::min(t0, up.dot(p));
      t1 = std::max(t1, up.dot(p));
    }
    const Eigen::Vector3d base = n * plane->offset;
    projector.screen = {base + s0 * right + t0 * up, base + s1 * right + t0 * up,
                        base + s1 * right + t1 * up, base + s0 * right + t1 * up};
  }
  result.projector = projector;
  return result;
}

}  // namespace studio::calibrate

#include "calibrate/geometry.h"

#include <opencv2/calib3d.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>

namespace studio::calibrate {
namespace {

// Similarity moving the points' centroid to 0 and their mean distance to sqrt(2) (Hartley).
Eigen::Matrix3d normaliser(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  double dist = 0;
  for (const auto& p : pts) dist += (p - mean).norm();
  dist /= static_cast<double>(pts.size());
  const double s = dist > 1e-12 ? std::sqrt(2.0) / dist : 1.0;
  Eigen::Matrix3d t;
  t << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  return t;
}

}  // namespace

Expected<Eigen::Matrix3d> fit_homography(const std::vector<Eigen::Vector2d>& plane_xy,
                                         const std::vector<Eigen::Vector2d>& pixels) {
  if (plane_xy.size() != pixels.size() || plane_xy.size() < 4)
    return fail("homography: need >= 4 point pairs");
  const Eigen::Matrix3d tp = normaliser(plane_xy), ti = normaliser(pixels);
  Eigen::MatrixXd a(2 * plane_xy.size(), 9);
  for (size_t i = 0; i < plane_xy.size(); ++i) {
    const Eigen::Vector3d p = tp * plane_xy[i].homogeneous();
    const Eigen::Vector3d q = ti * pixels[i].homogeneous();
    a.row(2 * i) << p.x(), p.y(), 1, 0, 0, 0, -q.x() * p.x(), -q.x() * p.y(), -q.x();
    a.row(2 * i + 1) << 0, 0, 0, p.x(), p.y(), 1, -q.y() * p.x(), -q.y() * p.y(), -q.y();
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  const auto& sv = svd.singularValues();
  if (!(sv(7) > 1e-9 * sv(0))) return fail("homography: the points are degenerate (collinear)");
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d out = ti.inverse() * hn * tp;
  if (std::abs(out(2, 2)) > 1e-15) out /= out(2, 2);
  if (!out.allFinite()) return fail("homography: not finite");
  return out;
}

Expected<Eigen::Vector2d> focal_from_homographies(const std::vector<Eigen::Matrix3d>& homographies,
                                                  double cx, double cy) {
  Eigen::Matrix3d shift;
  shift << 1, 0, -cx, 0, 1, -cy, 0, 0, 1;
  // Zhang's constraints on B = diag(1/fx^2, 1/fy^2, 1): h1' B h2 = 0, h1' B h1 = h2' B h2.
  std::vector<Eigen::Vector3d> rows;  // a * b1 + b * b2 + c = 0
  for (const Eigen::Matrix3d& h0 : homographies) {
    Eigen::Matrix3d h = shift * h0;
    h /= h.norm();
    const Eigen::Vector3d c1 = h.col(0), c2 = h.col(1);
    rows.emplace_back(c1.x() * c2.x(), c1.y() * c2.y(), c1.z() * c2.z());
    rows.emplace_back(c1.x() * c1.x() - c2.x() * c2.x(), c1.y() * c1.y() - c2.y() * c2.y(),
                      c1.z() * c1.z() - c2.z() * c2.z());
  }
  if (rows.empty()) return fail("focal initialisation: no views");
  Eigen::MatrixXd a(rows.size(), 2);
  Eigen::VectorXd b(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    a.row(i) << rows[i].x(), rows[i].y();
    b(i) = -rows[i].z();
  }
  if (homographies.size() >= 2) {
    const Eigen::Vector2d x = a.colPivHouseholderQr().solve(b);
    if (x.x() > 0 && x.y() > 0) {
      const Eigen::Vector2d f(1 / std::sqrt(x.x()), 1 / std::sqrt(x.y()));
      if (f.allFinite() && f.x() / f.y() > 0.5 && f.x() / f.y() < 2) return f;
    }
  }
  // Square pixels: one unknown.
  const Eigen::VectorXd col = a.col(0) + a.col(1);
  const double denom = col.squaredNorm();
  if (denom < 1e-300) return fail("focal initialisation: every view is fronto-parallel");
  const double b1 = col.dot(b) / denom;
  if (!(b1 > 0)) return fail("focal initialisation: the views do not determine a focal length");
  const double f = 1 / std::sqrt(b1);
  if (!std::isfinite(f)) return fail("focal initialisation: not finite");
  return Eigen::Vector2d(f, f);
}

Expected<Rigid3> planar_pose(const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
                             const std::vector<Eigen::Vector2d>& pixels) {
  if (target_points.size() != pixels.size() || pixels.size() < 4)
    return fail("planar pose: need >= 4 points");
  const Eigen::Matrix3d k_inv = camera.intrinsics.K().inverse();
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d distorted = (k_inv * pixels[i].homogeneous()).hnormalized();
    const Eigen::Vector2d ideal = undistort(camera.distortion, distorted);
    object.emplace_back(target_points[i].x(), target_points[i].y(), target_points[i].z());
    image.emplace_back(ideal.x(), ideal.y());
  }
  cv::Mat rvec, tvec;
  const cv::Mat eye = cv::Mat::eye(3, 3, CV_64F);
  bool ok = false;
  try {
    ok = cv::solvePnP(object, image, eye, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE);
    if (ok) ok = cv::solvePnP(object, image, eye, cv::noArray(), rvec, tvec, true,
                              cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception& e) {
    return fail(std::string("planar pose: ") + e.what());
  }
  if (!ok) return fail("planar pose: PnP failed");
  const Eigen::Vector3d r(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  if (!r.allFinite() || !t.allFinite()) return fail("planar pose: not finite");
  const double angle = r.norm();
  const Eigen::Quaterniond q = angle < 1e-15
                                   ? Eigen::Quaterniond::Identity()
                                   : Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle));
  return Rigid3(q, t);
}

Expected<Eigen::Vector3d> triangulate(const std::vector<Camera>& cameras,
                                      const std::vector<Eigen::Vector2d>& pixels) {
  if (cameras.size() != pixels.size() || cameras.size() < 2)
    return fail("triangulate: need >= 2 cameras with one pixel each");
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Eigen::Vector3d d = cameras[i].pixel_ray_in_world(pixels[i]).normalized();
    const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += m;
    b += m * cameras[i].centre_in_world();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  if (!(eig.eigenvalues()(0) > 1e-10 * cameras.size()))
    return fail("triangulate: the rays are parallel");
  const Eigen::Vector3d x = a.ldlt().solve(b);
  for (const Camera& c : cameras)
    if (!((c.cam_from_world * x).z() > 0)) return fail("triangulate: the point is behind a camera");
  if (!x.allFinite()) return fail("triangulate: not finite");
  return x;
}

}  // namespace studio::calibrate

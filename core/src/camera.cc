#include "core/camera.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <string>

namespace studio {
namespace {

using Coefficients = DistortionPolynomial;
Coefficients coefficients(const Distortion& d) { return polynomial(d); }

// Observed normalised point and, when jacobian != nullptr, d(observed)/d(ideal).
Eigen::Vector2d apply(const Coefficients& c, const Eigen::Vector2d& p, Eigen::Matrix2d* jacobian) {
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const Eigen::Vector2d out(x * radial + 2 * c.p1 * x * y + c.p2 * (r2 + 2 * x * x),
                            y * radial + c.p1 * (r2 + 2 * y * y) + 2 * c.p2 * x * y);
  if (jacobian != nullptr) {
    // d radial / d r2
    const double dr = c.k1 + r2 * (2 * c.k2 + 3 * c.k3 * r2);
    (*jacobian)(0, 0) = radial + 2 * x * x * dr + 2 * c.p1 * y + 6 * c.p2 * x;
    (*jacobian)(0, 1) = 2 * x * y * dr + 2 * c.p1 * x + 2 * c.p2 * y;
    (*jacobian)(1, 0) = 2 * x * y * dr + 2 * c.p1 * x + 2 * c.p2 * y;
    (*jacobian)(1, 1) = radial + 2 * y * y * dr + 6 * c.p1 * y + 2 * c.p2 * x;
  }
  return out;
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// Overflow on extreme inputs must not leak out as a camera with infinite or NaN parameters.
bool finite(const Intrinsics& k, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) && std::isfinite(k.cy) &&
         std::isfinite(k.skew) && k.fx > 0 && k.fy > 0 && R.allFinite() && t.allFinite();
}

}  // namespace

DistortionPolynomial polynomial(const Distortion& d) {
  switch (d.model) {
    case Distortion::Model::none:
      return {};
    case Distortion::Model::radial:
      return {d.rd3, d.rd5, 0, 0, 0};
    case Distortion::Model::opencv:
      return {d.k1, d.k2, d.k3, d.p1, d.p2};
  }
  return {};
}

Distortion Distortion::radial(double rd3, double rd5) {
  Distortion d;
  d.model = Model::radial;
  d.rd3 = rd3;
  d.rd5 = rd5;
  return d;
}

Distortion Distortion::opencv(double k1, double k2, double p1, double p2, double k3) {
  Distortion d;
  d.model = Model::opencv;
  d.k1 = k1;
  d.k2 = k2;
  d.p1 = p1;
  d.p2 = p2;
  d.k3 = k3;
  return d;
}

bool Distortion::is_identity() const {
  const Coefficients c = coefficients(*this);
  return c.k1 == 0 && c.k2 == 0 && c.k3 == 0 && c.p1 == 0 && c.p2 == 0;
}

Eigen::Vector2d distort(const Distortion& d, const Eigen::Vector2d& ideal) {
  if (d.is_identity()) return ideal;
  return apply(coefficients(d), ideal, nullptr);
}

Eigen::Vector2d undistort(const Distortion& d, const Eigen::Vector2d& observed) {
  if (d.is_identity() || !observed.allFinite()) return observed;
  const Coefficients c = coefficients(d);
  // 2-D Newton on f(p) = distort(p) - observed, started at the observed point, with step halving
  // when a full step does not reduce the residual (strong distortion near the image corners).
  Eigen::Vector2d p = observed;
  Eigen::Matrix2d J;
  Eigen::Vector2d residual = apply(c, p, &J) - observed;
  double norm = residual.norm();
  for (int iteration = 0; iteration < 20 && norm > 1e-15; ++iteration) {
    const double det = J.determinant();
    if (det == 0 || !std::isfinite(det)) break;
    const Eigen::Vector2d step = J.inverse() * residual;
    double scale = 1;
    Eigen::Vector2d candidate;
    Eigen::Matrix2d candidate_J;
    Eigen::Vector2d candidate_residual;
    double candidate_norm = norm;
    for (int halving = 0; halving < 30; ++halving, scale *= 0.5) {
      candidate = p - scale * step;
      candidate_residual = apply(c, candidate, &candidate_J) - observed;
      candidate_norm = candidate_residual.norm();
      if (candidate_norm < norm) break;
    }
    if (!(candidate_norm < norm)) break;  // no progress possible: at the numerical floor
    p = candidate;
    J = candidate_J;
    residual = candidate_residual;
    norm = candidate_norm;
    if ((scale * step).norm() < 1e-12 * (1 + p.norm()) && norm < 1e-12) break;
  }
  return p;
}

Eigen::Matrix3d Intrinsics::K() const {
  Eigen::Matrix3d k;
  k << fx, skew, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Intrinsics Intrinsics::from_K(const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d k = K / K(2, 2);
  Intrinsics in;
  in.fx = k(0, 0);
  in.fy = k(1, 1);
  in.cx = k(0, 2);
  in.cy = k(1, 2);
  in.skew = k(0, 1);
  return in;
}

Eigen::Vector3d Camera::centre_in_world() const {
  return -(cam_from_world.rotation.conjugate() * cam_from_world.translation);
}

Eigen::Vector3d Camera::axis_in_world() const {
  return (cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ()).normalized();
}

bool Camera::project(const Eigen::Vector3d& x_in_world, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d x = cam_from_world * x_in_world;
  if (!(x.z() > 0)) return false;
  const Eigen::Vector2d n = distort(distortion, Eigen::Vector2d(x.x() / x.z(), x.y() / x.z()));
  const Intrinsics& k = intrinsics;
  *pixel = Eigen::Vector2d(k.fx * n.x() + k.skew * n.y() + k.cx, k.fy * n.y() + k.cy);
  return true;
}

namespace {
Eigen::Vector2d ideal_normalised(const Camera& c, const Eigen::Vector2d& pixel) {
  const Intrinsics& k = c.intrinsics;
  const double y = (pixel.y() - k.cy) / k.fy;
  const double x = (pixel.x() - k.cx - k.skew * y) / k.fx;
  return undistort(c.distortion, Eigen::Vector2d(x, y));
}
}  // namespace

Eigen::Vector3d Camera::pixel_ray_in_world(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = ideal_normalised(*this, pixel);
  return (cam_from_world.rotation.conjugate() * Eigen::Vector3d(n.x(), n.y(), 1)).normalized();
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector2d& pixel, double depth) const {
  const Eigen::Vector2d n = ideal_normalised(*this, pixel);
  return cam_from_world.inverse() * Eigen::Vector3d(n.x() * depth, n.y() * depth, depth);
}

Eigen::Matrix<double, 3, 4> Camera::projection_matrix() const {
  return intrinsics.K() * cam_from_world.matrix3x4();
}

Cahv to_cahv(const Camera& camera) {
  const Eigen::Matrix3d R = camera.cam_from_world.R();
  const Eigen::Vector3d h = R.row(0).transpose(), v = R.row(1).transpose(),
                        a = R.row(2).transpose();
  const Intrinsics& k = camera.intrinsics;
  Cahv out;
  out.C = camera.centre_in_world();
  out.A = a;
  out.H = k.fx * h + k.skew * v + k.cx * a;
  out.V = k.fy * v + k.cy * a;
  return out;
}

Expected<Camera> camera_from_cahv(const Cahv& cahv, int width, int height) {
  if (width < 0 || height < 0) {
    return fail("CAHV: negative image size " + std::to_string(width) + "x" +
                std::to_string(height));
  }
  if (!finite(cahv.C) || !finite(cahv.A) || !finite(cahv.H) || !finite(cahv.V)) {
    return fail("CAHV: non-finite vector");
  }
  const double a_norm = cahv.A.norm();
  if (!(a_norm > 0)) return fail("CAHV: A is zero");
  // A of any length describes the same camera once H and V are divided by it too.
  const Eigen::Vector3d A = cahv.A / a_norm, H = cahv.H / a_norm, V = cahv.V / a_norm;
  Intrinsics k;
  k.cx = H.dot(A);
  k.cy = V.dot(A);
  const Eigen::Vector3d v_perp = V - k.cy * A;
  k.fy = v_perp.norm();
  if (!(k.fy > 1e-12 * (V.norm() + 1))) return fail("CAHV: V is parallel to A");
  const Eigen::Vector3d v = v_perp / k.fy;
  const Eigen::Vector3d h_perp = H - k.cx * A;
  k.skew = h_perp.dot(v);
  const Eigen::Vector3d h_rest = h_perp - k.skew * v;
  k.fx = h_rest.norm();
  if (!(k.fx > 1e-12 * (H.norm() + 1))) return fail("CAHV: H lies in the plane of A and V");
  const Eigen::Vector3d h = h_rest / k.fx;
  if (h.cross(v).dot(A) < 0) return fail("CAHV: H, V, A form a left-handed frame");
  Eigen::Matrix3d R;
  R.row(0) = h.transpose();
  R.row(1) = v.transpose();
  R.row(2) = A.transpose();
  if (!finite(k, R, -(R * cahv.C))) return fail("CAHV: numerically degenerate (overflow)");
  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.intrinsics = k;
  camera.cam_from_world = Rigid3(R, -(R * cahv.C));
  return camera;
}

Expected<Camera> camera_from_projection_matrix(const Eigen::Matrix<double, 3, 4>& P, int width,
                                               int height) {
  if (width < 0 || height < 0) {
    return fail("P: negative image size " + std::to_string(width) + "x" + std::to_string(height));
  }
  if (!P.allFinite()) return fail("P: non-finite entry");
  Eigen::Matrix3d M = P.leftCols<3>();
  Eigen::Vector3d p4 = P.col(3);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(0) > 0) || s(2) < 1e-12 * s(0)) {
    return fail("P: left 3x3 block is rank-deficient (not a finite projective camera)");
  }
  // P is defined up to scale, including its sign: choose the sign that makes det(K R) > 0 so that
  // with a positive K diagonal R is a proper rotation (and points in front have positive depth).
  if (M.determinant() < 0) {
    M = -M;
    p4 = -p4;
  }
  // RQ via QR of the row-reversed transpose: with J the exchange matrix,
  // (J M)^T = Q U  =>  M = (J U^T J) (J Q^T), J U^T J upper triangular, J Q^T orthogonal.
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  J(0, 2) = J(1, 1) = J(2, 0) = 1;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((J * M).transpose());
  const Eigen::Matrix3d U = qr.matrixQR().triangularView<Eigen::Upper>();
  const Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d K = J * U.transpose() * J;
  Eigen::Matrix3d R = J * Q.transpose();
  for (int i = 0; i < 3; ++i) {
    if (K(i, i) < 0) {
      K.col(i) *= -1;
      R.row(i) *= -1;
    }
  }
  // K has been forced exactly upper triangular by construction; t = K^-1 p4 before scaling K.
  const Eigen::Vector3d t = K.triangularView<Eigen::Upper>().solve(p4);
  if (R.determinant() < 0) return fail("P: decomposition gave an improper rotation");
  const Intrinsics intrinsics = Intrinsics::from_K(K);
  if (!finite(intrinsics, R, t)) return fail("P: numerically degenerate (overflow)");
  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.intrinsics = intrinsics;
  camera.cam_from_world = Rigid3(R, t);
  return camera;
}

}  // namespace studio

#pragma once
// Pinhole camera model, in the K / cam_from_world form and in the paper's CAHV form, with the
// paper's radial distortion (TCSVT 2004 §IV-A) or OpenCV's (for imports).
//
// Conventions
// - Camera frame: x right, y down, z forward (OpenCV). Pixel (0,0) is the centre of the top-left
//   pixel; pixel u grows with x, v with y.
// - Normalised image coordinates: (x/z, y/z) of a point in the camera frame.
// - Ideal pixel  = K * normalised;  observed pixel = K * distort(normalised).
// - The paper's radial model: r = r' + rd3 r'^3 + rd5 r'^5, where r' is the ideal (undistorted)
//   radius and r the observed (distorted) radius, both in normalised coordinates (pixels divided
//   by the focal length). distort() maps ideal → observed; undistort() inverts it by Newton.

#include <Eigen/Core>
#include <string>

#include "core/error.h"
#include "core/transform.h"

namespace studio {

struct Distortion {
  enum class Model { none, radial, opencv };
  Model model = Model::none;
  // Model::radial (the paper's):
  double rd3 = 0, rd5 = 0;
  // Model::opencv (Brown-Conrady as in cv::projectPoints with 5 coefficients):
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  static Distortion none() { return {}; }
  static Distortion radial(double rd3, double rd5);
  static Distortion opencv(double k1, double k2, double p1, double p2, double k3);
  bool is_identity() const;
};

// Both models in one polynomial form (what templated solvers evaluate): the paper's
// r = r' + rd3 r'^3 + rd5 r'^5 is OpenCV's radial part with k1 = rd3, k2 = rd5 and no tangential
// terms; Model::none is all zeros.
struct DistortionPolynomial {
  double k1 = 0, k2 = 0, k3 = 0, p1 = 0, p2 = 0;
};
DistortionPolynomial polynomial(const Distortion& d);

// Ideal normalised → observed normalised coordinates.
Eigen::Vector2d distort(const Distortion& d, const Eigen::Vector2d& ideal);
// Observed normalised → ideal normalised (Newton, converged to 1e-12 or 20 iterations).
Eigen::Vector2d undistort(const Distortion& d, const Eigen::Vector2d& observed);

struct Intrinsics {
  double fx = 1, fy = 1, cx = 0, cy = 0, skew = 0;
  Eigen::Matrix3d K() const;
  static Intrinsics from_K(const Eigen::Matrix3d& K);  // K(2,2) need not be 1: K is normalised
};

struct Camera {
  std::string id;
  int width = 0;
  int height = 0;
  Intrinsics intrinsics;
  Distortion distortion;
  Rigid3 cam_from_world;

  Eigen::Vector3d centre_in_world() const;
  // Unit optical axis (camera +z) in the world frame.
  Eigen::Vector3d axis_in_world() const;
  // Observed pixel of a world point. Returns false (pixel untouched) when the point is not in
  // front of the camera (z <= 0 in the camera frame).
  bool project(const Eigen::Vector3d& x_in_world, Eigen::Vector2d* pixel) const;
  // Observed pixel → unit direction of its ray in the world frame (through centre_in_world()).
  Eigen::Vector3d pixel_ray_in_world(const Eigen::Vector2d& pixel) const;
  // Observed pixel and depth (z in the camera frame) → the world point.
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel, double depth) const;
  // K [R | t]: the 3x4 projection matrix of the distortion-free part.
  Eigen::Matrix<double, 3, 4> projection_matrix() const;
  bool in_image(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < width - 0.5 && pixel.y() < height - 0.5;
  }
};

// The CAHV model (Yakimovsky & Cunningham), the paper's calibration form:
//   u = (x - C)·H / (x - C)·A,   v = (x - C)·V / (x - C)·A
// C: centre, A: unit optical axis, H = fx h' + cx A (+ skew v'), V = fy v' + cy A.
struct Cahv {
  Eigen::Vector3d C = Eigen::Vector3d::Zero();
  Eigen::Vector3d A = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d H = Eigen::Vector3d::UnitX();
  Eigen::Vector3d V = Eigen::Vector3d::UnitY();
};

// Exact conversions; distortion is carried separately (Camera::distortion).
Cahv to_cahv(const Camera& camera);
Expected<Camera> camera_from_cahv(const Cahv& cahv, int width, int height);
// RQ decomposition of a 3x4 projection matrix P ~ K [R | t] (any scale, any sign); K gets a
// positive diagonal and R a determinant of +1. Fails on a rank-deficient P.
Expected<Camera> camera_from_projection_matrix(const Eigen::Matrix<double, 3, 4>& P, int width, int height);

}  // namespace studio

#pragma once
// Closed-form pieces of calibration, reusable by projector calibration: planar homographies,
// Zhang's focal-length initialisation, planar pose (PnP) and multi-view triangulation.

#include <Eigen/Core>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/transform.h"

namespace studio::calibrate {

// H with pixel ~ H (X, Y, 1) for target points on z = 0 (normalised DLT, >= 4 points).
Expected<Eigen::Matrix3d> fit_homography(const std::vector<Eigen::Vector2d>& plane_xy,
                                         const std::vector<Eigen::Vector2d>& pixels);

// Zhang (2000) with the principal point known (cx, cy) and no skew: the focal lengths (fx, fy)
// from the homographies of >= 1 tilted views (square pixels assumed when only one view or the
// views cannot separate fx from fy). Fails when every view is fronto-parallel.
Expected<Eigen::Vector2d> focal_from_homographies(const std::vector<Eigen::Matrix3d>& homographies,
                                                  double cx, double cy);

// cam_from_target of a planar target (z = 0) from its distorted pixels (IPPE, then iterative
// refinement on the undistorted points), >= 4 points.
Expected<Rigid3> planar_pose(const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
                             const std::vector<Eigen::Vector2d>& pixels);

// The world point nearest (least squares) to the rays of >= 2 observed pixels of calibrated
// cameras. Fails when the rays are (nearly) parallel or a point lies behind a camera.
Expected<Eigen::Vector3d> triangulate(const std::vector<Camera>& cameras,
                                      const std::vector<Eigen::Vector2d>& pixels);

}  // namespace studio::calibrate

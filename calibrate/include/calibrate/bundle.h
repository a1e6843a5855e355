#pragma once
// One Ceres problem over every camera's intrinsics, every camera pose and every target pose
// (TCSVT 2004 §IV-A: "iterative minimisation of all camera and target-pose parameters").
//
// Model (core/camera.h): x_cam = cam_from_world * world_from_target * X_target,
// x' = (x/z, y/z), r'^2 = |x'|^2, observed normalised = x' (1 + rd3 r'^2 + rd5 r'^4)
// (the paper's r = r' + rd3 r'^3 + rd5 r'^5), pixel = (f x + cx, f a y + cy) with f the focal
// length and a the aspect ratio (fy = f a). Residual = projected − observed pixel.
//
// Parameter blocks: per camera intrinsics [f, a, cx, cy, rd3, rd5] (any subset fixed) and pose
// cam_from_world [angle-axis, t]; per frame world_from_target [angle-axis, t] (free), or
// [theta, tx, tz] (floor: target on y = 0, rotated by theta about +y — a parameterisation, not a
// soft prior), or nothing (fixed: the origin frame). The same solve serves single-camera
// refinement (camera pose fixed at identity) and held-out scoring (cameras fixed).
// All Ceres cost functions live in src/bundle.cc (one translation unit).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "calibrate/observations.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/transform.h"

namespace studio::calibrate {

struct IntrinsicsFixed {
  bool focal = false;            // f (and a)
  bool aspect = false;           // a = fy / fx
  bool principal_point = false;  // cx, cy
  bool rd3 = false;
  bool rd5 = false;
  bool all() const { return focal && principal_point && rd3 && rd5; }
};

struct BundleCamera {
  Camera camera;  // intrinsics (skew ignored), Distortion::radial, cam_from_world
  IntrinsicsFixed fixed;
  bool fix_pose = false;
};

struct BundleFrame {
  Placement placement = Placement::free;  // origin = pose fixed
  Rigid3 world_from_target;
};

struct BundleObservation {
  int camera = 0;
  int frame = 0;
  int point = 0;
  Eigen::Vector2d pixel;
};

struct BundleOptions {
  enum class Loss { none, huber, cauchy };
  Loss loss = Loss::huber;
  double loss_scale_px = 1.0;  // residual norm where the robust loss leaves the quadratic
  int max_iterations = 100;
  int threads = 2;
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  // Called after every iteration with its number and the current (robustified-cost) RMS, px.
  std::function<void(int iteration, double rms_px)> on_iteration;
  Expected<void> validate() const;
};

struct BundleSummary {
  int iterations = 0;
  double initial_rms_px = 0;  // sqrt(mean |residual|^2) before/after, from the robustified cost
  double final_rms_px = 0;
  double seconds = 0;
  bool usable = false;
  std::string report;  // Ceres' one-line summary
};

// Refines cameras and frames in place. Fails (one line) on inconsistent indices or when Ceres
// reports the problem unusable.
Expected<BundleSummary> solve_bundle(const std::vector<Eigen::Vector3d>& target_points,
                                     const std::vector<BundleObservation>& observations,
                                     std::vector<BundleCamera>* cameras,
                                     std::vector<BundleFrame>* frames,
                                     const BundleOptions& options);

// projected − observed pixel for one observation under the current state (same model as above).
Eigen::Vector2d reprojection_residual(const std::vector<Eigen::Vector3d>& target_points,
                                      const BundleObservation& observation,
                                      const std::vector<BundleCamera>& cameras,
                                      const std::vector<BundleFrame>& frames);

// The floor parameterisation: target on y = 0, face up, rotated by theta about +y, its point 0 at
// (tx, 0, tz). floor_pose(0, 0, 0) is the origin frame's pose.
Rigid3 floor_pose(double theta, double tx, double tz);
// The nearest floor pose's parameters [theta, tx, tz] for any world_from_target.
Eigen::Vector3d floor_parameters(const Rigid3& world_from_target);

}  // namespace studio::calibrate

#pragma once
// One-stage multi-camera calibration (TCSVT 2004 §IV-A): every camera's intrinsics and pose and
// every target pose from synchronous views of a planar target, in one robust Ceres solve.
//
// Pipeline: per camera, Zhang's focal length from the views' homographies (principal point at
// the image centre) and a planar pose per view, refined per camera; poses chained camera → frame
// → camera through shared frames from the gauge; one bundle over everything (bundle.h); outlier
// observations (residual > max(outlier_min_px, outlier_sigmas · σ̂), σ̂ from the median residual)
// dropped and the solve repeated; a last plain least-squares solve on the inliers. Held-out
// frames (flagged, and/or k-fold) are left out of the solve; afterwards their target poses are
// fitted with the cameras fixed and their residuals scored.
//
// Gauge: the origin frame (placement origin) fixes the studio frame (observations.h). Without an
// origin frame the gauge is free: the first camera is the studio frame (cam_from_world = I);
// floor frames then have no meaning and are rejected. Scale comes from the target spacing.
// RMS everywhere is sqrt(mean |projected − observed|^2) over observations, in pixels (the
// convention of cv::calibrateCamera / cv::stereoCalibrate).

#include <functional>
#include <string>
#include <vector>

#include "calibrate/bundle.h"
#include "calibrate/observations.h"
#include "core/camera.h"
#include "core/error.h"

namespace studio::calibrate {

struct CalibrationOptions {
  IntrinsicsFixed fixed;          // applied to every camera
  BundleOptions bundle;           // robust loss, iterations, threads
  double outlier_sigmas = 5.0;
  double outlier_min_px = 0.5;
  int outlier_rounds = 3;
  bool final_least_squares = true;
  int k_fold = 0;                 // > 1: additionally score k-fold cross-validation
  int min_points_per_view = 6;    // views with fewer points are ignored
  std::function<void(const std::string&)> progress;  // one line per step/iteration
  Expected<void> validate() const;
};

struct ScoredObservation {
  std::string camera_id;
  std::string frame_id;
  int point = 0;
  Eigen::Vector2d pixel;     // observed
  Eigen::Vector2d residual;  // projected − observed
};

struct CameraStats {
  std::string id;
  int observations = 0;  // inliers in the solve
  int outliers = 0;
  double rms_px = 0;
  double heldout_rms_px = 0;
  int heldout_observations = 0;
};

struct FrameStats {
  std::string id;
  Placement placement = Placement::free;
  bool held_out = false;
  int observations = 0;
  double rms_px = 0;
  Rigid3 world_from_target;
};

struct CalibrationResult {
  std::vector<Camera> cameras;  // in Observations::cameras order
  double rms_px = 0;            // inliers of the solved frames
  int observations = 0;
  double heldout_rms_px = 0;    // flagged held-out frames (0 if none)
  int heldout_observations = 0;
  double kfold_rms_px = 0;      // pooled k-fold held-out RMS (0 if k_fold <= 1)
  int kfold_observations = 0;
  std::vector<CameraStats> per_camera;
  std::vector<FrameStats> per_frame;
  std::vector<ScoredObservation> outliers;
  std::vector<ScoredObservation> inliers;  // every solved inlier (residual plots)
  std::vector<ScoredObservation> heldout;  // every held-out observation
  int iterations = 0;       // Ceres iterations of all solves
  double seconds = 0;       // wall time of calibrate_cameras
  std::string gauge;        // "origin frame F" or "camera C (free gauge)"
};

Expected<CalibrationResult> calibrate_cameras(const Observations& observations,
                                              const std::vector<Eigen::Vector3d>& target_points,
                                              const CalibrationOptions& options);

}  // namespace studio::calibrate

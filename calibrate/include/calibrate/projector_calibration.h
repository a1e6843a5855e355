#pragma once
// Projector calibration (TCSVT 2004 §V-C/D: a projector is an inverse camera; the screen is the
// retro-reflective cloth it lights). Input: for each feature of a projected pattern, its projector
// pixel (exact: the pattern is drawn there) and where two or more calibrated studio cameras saw it.
//
// Pipeline:
// 1. Triangulation of every feature: multi-view DLT on the cameras' undistorted observations
//    (Hartley & Zisserman §12.2), then Ceres refinement of the reprojection error in the cameras'
//    pixels through their full model (core/camera.h, distortion included). A feature is dropped
//    (counted) when it has < 2 views, the views are nearly parallel, the point is behind a camera,
//    or its refined RMS exceeds max_triangulation_rms_px.
// 2. Screen plane: least squares (smallest singular vector of the centred points) over the
//    features on the screen surface, with outliers beyond plane_outlier_sigmas dropped and the fit
//    repeated; normal oriented towards the projector.
// 3. Resection of the projector: normalised DLT for P ~ K [R | t] over all triangulated features,
//    RQ-decomposed into K and cam_from_world (core camera_from_projection_matrix), then Ceres
//    refinement of the reprojection error in projector pixels over fx, fy, cx, cy (optionally the
//    paper's radial rd3, rd5) and the pose, with a Huber loss (points fixed); then one joint Ceres
//    solve over the projector and every point, the projector being one more camera that observes
//    each feature exactly at its pattern pixel (errors in the triangulated points no longer bias
//    the pose; the studio cameras stay fixed). The DLT needs points on at least two
//    surfaces (the cloth alone is one plane, and one plane does not determine K and the pose: 8
//    equations for 10 unknowns): the pattern must also fall on the floor in front of the cloth, a
//    second wall, or a board held at one or more positions. Depth spread is what pins the
//    projector's distance against its focal length: on the synthetic studio of the unit test
//    (projector ~5.7 m from the cloth, 0.3 px detection noise), cloth + floor alone leave 4-34 mm
//    of error along the optical axis (and up to 0.6 % in focal length); adding a white board held
//    in the beam at two distances (~2.5 m and ~4 m from the projector) brings it to ~1-2 mm.
// 4. Screen corners: the given corners (e.g. measured) projected onto the fitted plane, or, when
//    none are given, the bounding rectangle of the screen features in the plane with its up edge
//    along the studio's +y projected into the plane (rig order lower-left, lower-right,
//    upper-right, upper-left, seen from the projector's side).

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/rig.h"

namespace studio::calibrate {

struct PatternView {
  int camera = 0;         // index into the cameras given to calibrate_projector()
  Eigen::Vector2d pixel;  // observed (distorted) camera pixel
};

struct PatternFeature {
  Eigen::Vector2d projector_pixel;  // where the pattern draws the feature
  int surface = 0;                  // which surface it fell on (screen_surface = the cloth)
  std::vector<PatternView> views;
};

struct ProjectorCalibrationOptions {
  std::string id = "proj0";
  int width = 1920;  // projector image size, pixels
  int height = 1080;
  int screen_surface = 0;
  bool fit_radial = false;  // also fit rd3, rd5 (the paper's model)
  double max_triangulation_rms_px = 2.0;
  double plane_outlier_sigmas = 4.0;
  double loss_scale_px = 2.0;  // Huber scale of the refinements (camera pixels)
  // Joint refinement (step 3b): the projector's parameters and every point together, weighted by
  // the expected noise of the cameras' detections and of the projector's pixels (exact by
  // construction, up to the pattern's rendering).
  bool joint = true;
  double camera_noise_px = 0.3;
  double projector_noise_px = 0.05;
  // The features must spread at least this far (RMS) from their best plane (see step 3).
  double min_off_plane_m = 0.05;
  int max_iterations = 200;
  // Optional measured corners: projected onto the fitted plane instead of the features' extent.
  std::optional<std::array<Eigen::Vector3d, 4>> screen_corners;
  Expected<void> validate() const;
};

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, towards the projector
  double offset = 0;                                  // normal . x = offset on the plane
  double distance(const Eigen::Vector3d& x) const { return normal.dot(x) - offset; }
};

struct ProjectorCalibrationResult {
  Projector projector;  // camera (K, radial, cam_from_world, size, id) and screen corners
  Plane screen_plane;
  std::vector<Eigen::Vector3d> points;  // triangulated features (NaN for dropped ones)
  int features = 0;                     // given
  int triangulated = 0;                 // kept after triangulation
  int screen_points = 0;                // used by the plane fit (inliers)
  double triangulation_rms_px = 0;      // cameras' reprojection RMS over kept features
  double plane_rms_m = 0;               // RMS distance of the screen inliers from the plane
  double dlt_rms_px = 0;                // projector reprojection RMS after the DLT
  double resection_rms_px = 0;          // ... after the resection refinement (points fixed)
  double rms_px = 0;                    // ... after the joint refinement (its points)
  double camera_rms_px = 0;             // cameras' reprojection RMS of the joint solve's points
  int iterations = 0;
};

// Steps 1-4. Errors, one line: invalid options, a camera index out of range, fewer than 6
// triangulated features, fewer than 3 on the screen, all features on one plane, a degenerate or
// unusable solve.
Expected<ProjectorCalibrationResult> calibrate_projector(
    const std::vector<Camera>& cameras, const std::vector<PatternFeature>& features,
    const ProjectorCalibrationOptions& options);

// Puts the projector into the rig: replaces the one with the same id, else appends it.
void store_projector(Rig* rig, const Projector& projector);

// ---- the steps, for tests and tools -------------------------------------------------------

// Multi-view DLT from >= 2 views (undistorted through each camera's model). Fails on fewer than 2
// views, rays too close to parallel, or a point behind a camera.
Expected<Eigen::Vector3d> triangulate_dlt(const std::vector<Camera>& cameras,
                                          const std::vector<PatternView>& views);
// Ceres refinement of a triangulated point: minimises the cameras' pixel reprojection error.
// Returns the point and its RMS reprojection error (px).
Expected<std::pair<Eigen::Vector3d, double>> refine_point(const std::vector<Camera>& cameras,
                                                          const std::vector<PatternView>& views,
                                                          const Eigen::Vector3d& initial);

// Least-squares plane through >= 3 non-collinear points.
Expected<Plane> fit_plane(const std::vector<Eigen::Vector3d>& points);

// Normalised DLT for P ~ K [R | t] from >= 6 non-coplanar point/pixel pairs, decomposed into a
// camera of the given size.
Expected<Camera> resect_dlt(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels, int width, int height);

}  // namespace studio::calibrate

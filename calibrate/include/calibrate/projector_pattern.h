#pragma once
// The projected calibration pattern and its detection (issue 15 item 4; TCSVT 2004 §III-C, §V-C):
// the projector shows a ChArUco board, two or more calibrated studio cameras see it on the cloth
// (or on a board held in the beam), and every ChArUco corner seen by at least two cameras becomes
// a PatternFeature for calibrate_projector() (calibrate/projector_calibration.h) — its projector
// pixel is exact (the pattern draws it there), its views are the detections.
//
// Getting a usable view (paper §III-C): the retro-reflective cloth sends the projector's light
// back to the projector, and each camera mostly sees its own LED ring's blue light; switch the
// ring off (or dim it) and lengthen the exposure (4x or more) for the capture, so the pattern's
// white squares stand out from the cloth. A white board held in the beam shows the pattern with
// full contrast and gives the depth spread the projector's resection needs (projector_calibration.h
// step 3): capture the cloth once and the board at two or more distances.
//
// Pattern geometry: the board (cols x rows squares of square_px projector pixels, ChArUco markers
// of marker_px) has its top-left outer corner at the pixel EDGE (x0, y0): square (c, r) covers
// pixels [x0 + c s, x0 + (c + 1) s) x [y0 + r s, ...). Inner corner id = r (cols - 1) + c
// (target.h) lies between pixels, at pixel-centre coordinates (x0 + (c + 1) s - 0.5, y0 + (r + 1) s
// - 0.5) (core/camera.h: pixel (0, 0) is the centre of the top-left pixel). A white border of
// margin_px surrounds the squares (the markers' quiet zone); the rest of the frame is black.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "calibrate/projector_calibration.h"
#include "calibrate/target.h"
#include "core/camera.h"
#include "core/error.h"

namespace studio::calibrate {

struct ProjectedPattern {
  TargetSpec board;  // kind charuco; spacing and marker in projector PIXELS (integers)
  int x0 = 0, y0 = 0;
  int margin_px = 0;
  // A ChArUco spec with integral square/marker sizes, the board and its margin inside the frame.
  Expected<void> validate(int width, int height) const;
  int square_px() const { return static_cast<int>(board.spacing + 0.5); }
  // Projector pixel (centre convention) of inner corner `id`.
  Eigen::Vector2d projector_pixel(int id) const;
};

// The W x H projector frame showing the pattern (8-bit grey: 255 white, 0 black).
Expected<cv::Mat> draw_pattern(const ProjectedPattern& pattern, int width, int height);

// One capture: every camera's image of the pattern at one instant (index = camera; an empty
// image = that camera took none), on the cloth (board = false) or on a board in the beam.
struct PatternCapture {
  std::string name;
  std::vector<cv::Mat> images;
  bool board = false;
};

struct CaptureReport {
  std::string name;
  std::vector<int> detected;  // corners detected per camera
  int features = 0;           // corners seen by >= 2 cameras
  int screen = 0;             // of those, on the screen plane (cloth captures)
};

// Detects the pattern in each image and joins the detections by corner id; corners seen by fewer
// than two cameras are dropped. Errors: image count differs from the camera count, an image whose
// size differs from its camera, a detection error.
Expected<std::vector<PatternFeature>> capture_features(const std::vector<Camera>& cameras,
                                                       const PatternCapture& capture,
                                                       const ProjectedPattern& pattern,
                                                       std::vector<int>* detected = nullptr);

// The cloth capture's features are split into surfaces: each feature is triangulated
// (triangulate_dlt), the plane with the most features within tolerance_m (RANSAC over triples,
// deterministic, then refit) is the screen (surface `screen`), the rest get `other`. Features
// that do not triangulate get `other`. Returns how many are on the screen.
int label_screen(const std::vector<Camera>& cameras, std::vector<PatternFeature>* features,
                 int screen, int other, double tolerance_m = 0.02);

// Every capture through capture_features (cloth captures labelled by label_screen; board capture
// k gets surface 2 + k, the cloth's non-screen features surface 1, the screen
// options.screen_surface = 0), then calibrate_projector(). Errors: those of the steps, with the
// capture's name.
struct PatternCalibration {
  ProjectorCalibrationResult result;
  std::vector<CaptureReport> captures;
};
Expected<PatternCalibration> calibrate_projector_from_captures(
    const std::vector<Camera>& cameras, const std::vector<PatternCapture>& captures,
    const ProjectedPattern& pattern, ProjectorCalibrationOptions options);

}  // namespace studio::calibrate

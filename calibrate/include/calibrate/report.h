#pragma once
// Calibration report: JSON for machines and one residual plot PNG per camera.
//
// JSON: {"rms_px", "observations", "heldout": {"rms_px", "observations"}, "kfold": {...},
//        "iterations", "seconds", "gauge", "cameras": [{"id", "observations", "outliers",
//        "rms_px", "heldout_rms_px", "fx", "fy", "cx", "cy", "rd3", "rd5", "centre"}],
//        "frames": [{"id", "placement", "held_out", "observations", "rms_px"}],
//        "outliers": [{"camera", "frame", "point", "u", "v", "residual_px"}]}

#include <string>

#include "calibrate/camera_calibration.h"
#include "core/error.h"

namespace studio::calibrate {

std::string report_json(const CalibrationResult& result);

// Writes DIR/residuals_<camera_id>.png per camera: the image area with each observation's
// residual drawn magnified (inliers green, held-out blue, outliers red) and a scatter of the
// residual vectors with a circle at the camera's RMS. Returns the files written.
Expected<std::vector<std::string>> write_residual_plots(const CalibrationResult& result,
                                                        const std::string& dir);

}  // namespace studio::calibrate

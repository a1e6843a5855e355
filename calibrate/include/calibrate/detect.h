#pragma once
// Target detection in images (OpenCV): chessboards (cv::findChessboardCorners + cornerSubPix)
// and ChArUco boards (OpenCV contrib aruco, 4.6 API; partial views give the corners seen). ChArUco
// corners are refined again in the pixel-centre convention (OpenCV 4.6 returns them ~0.4 px off)
// and a corner whose id disagrees with its neighbours (a misread marker) is dropped.

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calibrate/observations.h"
#include "calibrate/target.h"
#include "core/error.h"

namespace studio::calibrate {

// Points of the target found in one 8-bit grey or BGR image (empty when not found). Chessboard
// corners come in OpenCV's order (ids of target.h); a grid target cannot be detected.
Expected<std::vector<PointObservation>> detect_target(const cv::Mat& image, const TargetSpec& target);

// Reads DIR/<camera_id>/<frame_id>.png|jpg|jpeg (DESIGN §6), detects the target in each, and
// returns the observations (all frames free; cameras and frames sorted by id). Fails with one
// line on an unreadable image, a camera folder without images, no camera folders, or a target
// never detected. progress gets one line per image.
Expected<Observations> detect_directory(const std::string& dir, const TargetSpec& target,
                                        const std::function<void(const std::string&)>& progress = {});

}  // namespace studio::calibrate

#pragma once
// The Middlebury dinoSparseRing (../shared/data/middlebury_dino, provenance in its README) as
// tests use it: the views listed in dinoSR_good_silhouette_images.txt with their calibrated
// cameras, colour images and silhouettes by Middlebury's own recipe (threshold the black
// background at 0.19 of full scale, dilate 10 px, erode 7 px). Tests and benchmarks only.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/run_mask.h"

namespace studio::testing {

struct DinoViews {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> rgb;          // CV_8UC3, RGB order
  std::vector<cv::Mat> silhouettes;  // CV_8U, 255 = object
  std::vector<RunMask> masks;        // the silhouettes as run masks
  // The object's tight bounding box (the README's) grown by `pad` metres.
  static Eigen::Vector3d box_min(double pad);
  static Eigen::Vector3d box_max(double pad);
};

// The shared data folder's dino (dir = <shared data>/middlebury_dino). Fails with one line when a
// file is missing or unreadable (the caller decides whether that skips).
Expected<DinoViews> load_middlebury_dino(const std::string& dir);

}  // namespace studio::testing

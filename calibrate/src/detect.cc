#include "calibrate/detect.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include "calibrate/text.h"
#include <map>

namespace studio::calibrate {

namespace fs = std::filesystem;

namespace {

// OpenCV 4.6's interpolateCornersCharuco returns corners about +0.4 px off in x and y (measured
// against the simulator's exact projections, calibrate/sim_calibration_test.cc): its internal
// cornerSubPix stops at 0.1 px steps and its output is not in the pixel-centre convention of
// cornerSubPix / findChessboardCorners that core/camera.h uses. The corners are refined again
// here, to convergence, in that convention. The window half-size is 0.35 of the distance to the
// nearest detected neighbour corner (2..5 px), so it never reaches the next corner; closer in,
// the marker borders (1/8 of a square from the corner) are symmetric about it.
void refine_charuco_corners(const cv::Mat& grey, int corners_per_row, const std::vector<int>& ids,
                            std::vector<cv::Point2f>* corners) {
  const std::vector<cv::Point2f> start = *corners;
  for (size_t k = 0; k < start.size(); ++k) {
    double nearest = 1e9;
    for (size_t m = 0; m < start.size(); ++m) {
      const int a = ids[k], b = ids[m];
      const bool row_neighbour = std::abs(a - b) == 1 && a / corners_per_row == b / corners_per_row;
      if (row_neighbour || std::abs(a - b) == corners_per_row)
        nearest = std::min(nearest, static_cast<double>(cv::norm(start[m] - start[k])));
    }
    const int half = nearest > 1e8 ? 5 : std::clamp(static_cast<int>(0.35 * nearest), 2, 5);
    std::vector<cv::Point2f> one{start[k]};
    cv::cornerSubPix(grey, one, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-4));
    (*corners)[k] = one[0];
  }
}

// A misread marker gives corners a wrong id, whole squares away from where the id belongs
// (seen on simulated images: 43 px off). Each corner is checked against a homography fitted
// (RANSAC) to the detected corners within two squares of it, without it: further than a quarter
// of the local square size from its prediction, it is dropped. Corners with fewer than five
// neighbours cannot be judged and are kept.
void drop_inconsistent_ids(int per_row, std::vector<int>* ids, std::vector<cv::Point2f>* corners) {
  std::vector<int> keep_ids;
  std::vector<cv::Point2f> keep;
  for (size_t k = 0; k < ids->size(); ++k) {
    const int ik = (*ids)[k] % per_row, jk = (*ids)[k] / per_row;
    std::vector<cv::Point2f> board, image;
    for (size_t m = 0; m < ids->size(); ++m) {
      const int im = (*ids)[m] % per_row, jm = (*ids)[m] / per_row;
      if (m == k || std::abs(im - ik) > 2 || std::abs(jm - jk) > 2) continue;
      board.emplace_back(static_cast<float>(im), static_cast<float>(jm));
      image.push_back((*corners)[m]);
    }
    bool ok = true;
    if (board.size() >= 5) {
      const cv::Mat h = cv::findHomography(board, image, cv::RANSAC, 1.0);
      if (!h.empty()) {
        std::vector<cv::Point2f> at = {{float(ik), float(jk)}, {float(ik + 1), float(jk)},
                                       {float(ik), float(jk + 1)}},
                                 predicted;
        cv::perspectiveTransform(at, predicted, h);
        const double square = 0.5 * (cv::norm(predicted[1] - predicted[0]) +
                                     cv::norm(predicted[2] - predicted[0]));
        ok = cv::norm((*corners)[k] - predicted[0]) < std::max(1.5, 0.25 * square);
      }
    }
    if (ok) {
      keep_ids.push_back((*ids)[k]);
      keep.push_back((*corners)[k]);
    }
  }
  *ids = std::move(keep_ids);
  *corners = std::move(keep);
}

}  // namespace

Expected<std::vector<PointObservation>> detect_target(const cv::Mat& image, const TargetSpec& target) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    return fail("detect: expected an 8-bit grey or BGR image");
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else grey = image;
  std::vector<PointObservation> out;
  try {
    if (target.kind == TargetSpec::Kind::chessboard) {
      std::vector<cv::Point2f> corners;
      const bool found = cv::findChessboardCorners(
          grey, cv::Size(target.cols, target.rows), corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
      if (!found) return out;
      cv::cornerSubPix(grey, corners, cv::Size(11, 11), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
      for (size_t i = 0; i < corners.size(); ++i)
        out.push_back({static_cast<int>(i), Eigen::Vector2d(corners[i].x, corners[i].y)});
    } else if (target.kind == TargetSpec::Kind::charuco) {
      const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(target.dictionary);
      const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
          target.cols, target.rows, static_cast<float>(target.spacing),
          static_cast<float>(target.marker), dict);
      std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
      std::vector<int> marker_ids;
      const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
      params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
      cv::aruco::detectMarkers(grey, dict, marker_corners, marker_ids, params, rejected);
      if (marker_ids.empty()) return out;
      std::vector<cv::Point2f> corners;
      std::vector<int> ids;
      cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, board, corners, ids,
                                           cv::noArray(), cv::noArray(), 2);
      refine_charuco_corners(grey, target.cols - 1, ids, &corners);
      drop_inconsistent_ids(target.cols - 1, &ids, &corners);
      for (size_t i = 0; i < ids.size(); ++i)
        out.push_back({ids[i], Eigen::Vector2d(corners[i].x, corners[i].y)});
      std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.id < b.id; });
    } else {
      return fail("detect: a grid target has no image pattern; use chessboard or charuco");
    }
  } catch (const cv::Exception& e) {
    return fail(std::string("detect: OpenCV: ") + e.what());
  }
  return out;
}

Expected<Observations> detect_directory(const std::string& dir, const TargetSpec& target,
                                        const std::function<void(const std::string&)>& progress) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(dir + ": not a directory");
  std::vector<fs::path> camera_dirs;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory()) camera_dirs.push_back(e.path());
  if (ec) return fail(dir + ": " + ec.message());
  std::sort(camera_dirs.begin(), camera_dirs.end());
  if (camera_dirs.empty()) return fail(dir + ": no camera folders (expected DIR/<camera_id>/<frame_id>.png|jpg)");

  Observations obs;
  std::map<std::string, FrameObservations> frames;
  size_t images = 0, detected = 0;
  for (const fs::path& cdir : camera_dirs) {
    const std::string cam = cdir.filename().string();
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(cdir, ec)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (e.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
        files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) return fail(cdir.string() + ": no .png/.jpg images");
    CameraInfo info{cam, 0, 0};
    int seen = 0;
    for (const fs::path& file : files) {
      const cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
      if (image.empty()) return fail(file.string() + ": cannot read image");
      if (info.width == 0) {
        info.width = image.cols;
        info.height = image.rows;
      } else if (image.cols != info.width || image.rows != info.height) {
        return fail(format("{}: {}x{} image, but camera {} has {}x{} images", file.string(),
                                image.cols, image.rows, cam, info.width, info.height));
      }
      auto points = detect_target(image, target);
      if (!points) return fail(file.string() + ": " + points.error().message);
      ++images;
      const std::string frame_id = file.stem().string();
      FrameObservations& frame = frames[frame_id];
      frame.id = frame_id;
      if (!points->empty()) {
        frame.views.push_back({cam, std::move(*points)});
        ++detected;
        ++seen;
      }
      if (progress)
        progress(format("detect {}/{}: {} points", cam, file.filename().string(),
                             frame.views.empty() || frame.views.back().camera_id != cam
                                 ? 0
                                 : frame.views.back().points.size()));
    }
    obs.cameras.push_back(info);
  }
  if (detected == 0)
    return fail(format("target {} was detected in none of the {} images under {}",
                            target.to_string(), images, dir));
  for (auto& [id, frame] : frames)
    if (!frame.views.empty()) obs.frames.push_back(std::move(frame));
  return obs;
}

}  // namespace studio::calibrate

#pragma once
// A planar calibration target (chessboard or ChArUco) rendered into a virtual camera at a
// given pose, for calibration tests (issue 3 item 1; the paper's §IV-A target).
//
// Target frame: origin at the board's outer top-left corner (the corner of square (0, 0)),
// x along the squares_x direction, y along squares_y, z = x × y pointing INTO the board (the
// printed face looks towards -z). This is OpenCV's board frame: inner corner (i, j) is at
// ((i + 1) s, (j + 1) s, 0) with id j (squares_x - 1) + i, as cv::aruco::CharucoBoard numbers
// its chessboard corners. Square (0, 0) is black. ChArUco markers, their ids and bits come from
// cv::aruco's predefined dictionary and CharucoBoard layout (OpenCV 4.6), read once when the
// target is made; rendering itself uses no OpenCV.
//
// Rendering: pixels whose footprint crosses an edge are supersampled (supersample^2 rays), so
// edges are anti-aliased and corner detectors see sub-pixel-realistic images.

#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"

namespace studio::sim {

struct TargetSpec {
  enum class Kind { chessboard, charuco };
  Kind kind = Kind::chessboard;
  int squares_x = 11;  // squares; (squares_x - 1) x (squares_y - 1) inner corners
  int squares_y = 11;  // the paper's 1 m target with 100 points: 11 x 11 squares of 0.1 m
  double square = 0.1;       // metres
  double marker = 0.075;     // ChArUco marker side, metres (< square)
  int dictionary = 0;        // cv::aruco::PREDEFINED_DICTIONARY_NAME (0 = DICT_4X4_50)
  double margin = 0.05;      // white border around the squares, metres
  Expected<void> validate() const;

  int corner_count() const { return (squares_x - 1) * (squares_y - 1); }
  // Inner corners in the target frame (z = 0), indexed by id.
  std::vector<Eigen::Vector3d> corners() const;
};

struct TargetRender {
  uint64_t seed = 1;
  double noise_sigma = 1.5;    // grey levels
  int supersample = 8;         // rays per axis on edge pixels
  uint8_t white = 215, black = 28;
  bool blue_background = true; // behind the board: the lit blue cloth, else mid grey
  double shading = 0.1;        // brightness gradient across the board (uneven lighting)
  Expected<void> validate() const;
};

class Target {
 public:
  // Fails with one line on an invalid spec or an unknown ChArUco dictionary.
  static Expected<Target> create(const TargetSpec& spec);
  const TargetSpec& spec() const { return spec_; }

  // Renders the board at world_from_target into the camera's image (sized to the camera).
  void render(const Camera& camera, const Rigid3& world_from_target, const TargetRender& options,
              Image<Rgb8>* image) const;
  // True pixel of every inner corner (observed, with distortion); visible[i] is false when the
  // corner is behind the camera, outside the image or the board is seen from its back.
  void project_corners(const Camera& camera, const Rigid3& world_from_target,
                       std::vector<Eigen::Vector2d>* pixels, std::vector<bool>* visible) const;
  // Reflectance of the printed face at target-frame point (x, y): 1 white, 0 black; -1 off the
  // board (including outside the margin).
  int ink(double x, double y) const;

  struct Marker {
    int id = 0;
    Eigen::Vector2d origin, ex, ey;  // marker corner 0 and the edges to corners 1 and 3
    int cells = 0;                   // bits per side including the black border
    std::vector<uint8_t> white;      // cells x cells, row-major from corner 0
  };
  const std::vector<Marker>& markers() const { return markers_; }

 private:
  TargetSpec spec_;
  std::vector<int> marker_of_square_;  // squares_x * squares_y, -1 for none
  std::vector<Marker> markers_;
};

}  // namespace studio::sim

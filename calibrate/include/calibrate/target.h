#pragma once
// Planar calibration targets (DESIGN §6 SPEC): chessboards, ChArUco boards and plain point grids.
//
// Target frame: metres, the board plane is z = 0, x along a row (increasing column), y along a
// column (increasing row), so z points into the board, away from a camera that sees its face.
// Point ids:
// - chessboard / grid: id = row * cols + col, at (col * spacing, row * spacing, 0) — the order
//   of cv::findChessboardCorners with patternSize (cols, rows).
// - ChArUco (COLSxROWS squares): the (COLS-1) x (ROWS-1) inner corners, id = row * (COLS-1) + col,
//   at ((col + 1) * square, (row + 1) * square, 0) — the ids of cv::aruco::interpolateCornersCharuco.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::calibrate {

struct TargetSpec {
  enum class Kind { chessboard, charuco, grid };
  Kind kind = Kind::grid;
  int cols = 10;           // points per row (chessboard, grid) or squares along x (ChArUco)
  int rows = 10;           // rows of points (chessboard, grid) or squares along y (ChArUco)
  double spacing = 0.1;    // point spacing / square size, metres
  double marker = 0.0;     // ChArUco marker side, metres
  int dictionary = 0;      // cv::aruco::PREDEFINED_DICTIONARY_NAME (ChArUco)
  std::string dictionary_name;

  // Fails with one line naming the wrong field.
  Expected<void> validate() const;
  int point_count() const;
  // Points of the target in the target frame, indexed by point id.
  std::vector<Eigen::Vector3d> points() const;
  // The spec string this target was parsed from (canonical form).
  std::string to_string() const;
};

// Parses "chessboard:COLSxROWS:SPACING_M" (inner corners), "grid:COLSxROWS:SPACING_M" or
// "charuco:COLSxROWS:SQUARE_M:MARKER_M:DICT" (squares; DICT like DICT_5X5_100 or 5X5_100).
// (A FILE.yaml spec is read by the command-line tool, which owns YAML.)
Expected<TargetSpec> parse_target_spec(const std::string& spec);

}  // namespace studio::calibrate

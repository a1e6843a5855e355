#include "calibrate/target.h"

#include <opencv2/aruco/dictionary.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include "calibrate/text.h"
#include <sstream>

namespace studio::calibrate {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, sep)) out.push_back(part);
  if (!s.empty() && s.back() == sep) out.push_back("");
  return out;
}

bool parse_int(const std::string& s, int* out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_double(const std::string& s, double* out) {
  if (s.empty()) return false;
  try {
    size_t used = 0;
    *out = std::stod(s, &used);
    return used == s.size() && std::isfinite(*out);
  } catch (...) {
    return false;
  }
}

struct DictionaryName {
  const char* name;
  int id;
};
constexpr DictionaryName kDictionaries[] = {
    {"4X4_50", cv::aruco::DICT_4X4_50},     {"4X4_100", cv::aruco::DICT_4X4_100},
    {"4X4_250", cv::aruco::DICT_4X4_250},   {"4X4_1000", cv::aruco::DICT_4X4_1000},
    {"5X5_50", cv::aruco::DICT_5X5_50},     {"5X5_100", cv::aruco::DICT_5X5_100},
    {"5X5_250", cv::aruco::DICT_5X5_250},   {"5X5_1000", cv::aruco::DICT_5X5_1000},
    {"6X6_50", cv::aruco::DICT_6X6_50},     {"6X6_100", cv::aruco::DICT_6X6_100},
    {"6X6_250", cv::aruco::DICT_6X6_250},   {"6X6_1000", cv::aruco::DICT_6X6_1000},
    {"7X7_50", cv::aruco::DICT_7X7_50},     {"7X7_100", cv::aruco::DICT_7X7_100},
    {"7X7_250", cv::aruco::DICT_7X7_250},   {"7X7_1000", cv::aruco::DICT_7X7_1000},
    {"ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
};

int dictionary_size(int id) {
  switch (id) {
    case cv::aruco::DICT_4X4_50: case cv::aruco::DICT_5X5_50: case cv::aruco::DICT_6X6_50:
    case cv::aruco::DICT_7X7_50: return 50;
    case cv::aruco::DICT_4X4_100: case cv::aruco::DICT_5X5_100: case cv::aruco::DICT_6X6_100:
    case cv::aruco::DICT_7X7_100: return 100;
    case cv::aruco::DICT_4X4_250: case cv::aruco::DICT_5X5_250: case cv::aruco::DICT_6X6_250:
    case cv::aruco::DICT_7X7_250: case cv::aruco::DICT_ARUCO_ORIGINAL: return 250;
    default: return 1000;
  }
}

}  // namespace

Expected<void> TargetSpec::validate() const {
  const int min = kind == Kind::charuco ? 3 : 2;
  if (cols < min || rows < min || cols > 1000 || rows > 1000)
    return fail(format("target: {}x{} is out of range (at least {}x{})", cols, rows, min, min));
  if (!(spacing > 0) || !std::isfinite(spacing))
    return fail("target: the spacing must be a positive number of metres");
  if (kind == Kind::charuco) {
    if (!(marker > 0) || !(marker < spacing))
      return fail("target: the ChArUco marker side must be > 0 and smaller than the square");
    if (cols * rows / 2 > dictionary_size(dictionary))
      return fail(format("target: {} has too few markers for {}x{} squares",
                              dictionary_name, cols, rows));
  }
  return {};
}

int TargetSpec::point_count() const {
  return kind == Kind::charuco ? (cols - 1) * (rows - 1) : cols * rows;
}

std::vector<Eigen::Vector3d> TargetSpec::points() const {
  std::vector<Eigen::Vector3d> out;
  if (kind == Kind::charuco) {
    for (int r = 0; r < rows - 1; ++r)
      for (int c = 0; c < cols - 1; ++c) out.emplace_back((c + 1) * spacing, (r + 1) * spacing, 0);
  } else {
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) out.emplace_back(c * spacing, r * spacing, 0);
  }
  return out;
}

std::string TargetSpec::to_string() const {
  switch (kind) {
    case Kind::chessboard: return format("chessboard:{}x{}:{}", cols, rows, spacing);
    case Kind::grid: return format("grid:{}x{}:{}", cols, rows, spacing);
    case Kind::charuco:
      return format("charuco:{}x{}:{}:{}:DICT_{}", cols, rows, spacing, marker, dictionary_name);
  }
  return {};
}

Expected<TargetSpec> parse_target_spec(const std::string& spec) {
  const std::vector<std::string> parts = split(spec, ':');
  const std::string usage =
      "expected chessboard:COLSxROWS:SPACING_M, grid:COLSxROWS:SPACING_M or "
      "charuco:COLSxROWS:SQUARE_M:MARKER_M:DICT";
  if (parts.empty()) return fail("target spec '" + spec + "': " + usage);
  TargetSpec t;
  if (parts[0] == "chessboard") t.kind = TargetSpec::Kind::chessboard;
  else if (parts[0] == "grid") t.kind = TargetSpec::Kind::grid;
  else if (parts[0] == "charuco") t.kind = TargetSpec::Kind::charuco;
  else return fail("target spec '" + spec + "': " + usage);
  const size_t want = t.kind == TargetSpec::Kind::charuco ? 5 : 3;
  if (parts.size() != want) return fail("target spec '" + spec + "': " + usage);
  const std::vector<std::string> size = split(parts[1], 'x');
  if (size.size() != 2 || !parse_int(size[0], &t.cols) || !parse_int(size[1], &t.rows))
    return fail("target spec '" + spec + "': size '" + parts[1] + "' is not COLSxROWS");
  if (!parse_double(parts[2], &t.spacing))
    return fail("target spec '" + spec + "': '" + parts[2] + "' is not a number of metres");
  if (t.kind == TargetSpec::Kind::charuco) {
    if (!parse_double(parts[3], &t.marker))
      return fail("target spec '" + spec + "': '" + parts[3] + "' is not a number of metres");
    std::string name = parts[4];
    std::transform(name.begin(), name.end(), name.begin(), ::toupper);
    if (name.rfind("DICT_", 0) == 0) name = name.substr(5);
    bool found = false;
    for (const auto& d : kDictionaries) {
      if (name == d.name) {
        t.dictionary = d.id;
        t.dictionary_name = d.name;
        found = true;
      }
    }
    if (!found)
      return fail("target spec '" + spec + "': unknown ArUco dictionary '" + parts[4] +
                  "' (e.g. DICT_5X5_100)");
  }
  if (auto v = t.validate(); !v) return std::unexpected(v.error());
  return t;
}

}  // namespace studio::calibrate

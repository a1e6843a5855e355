// Text importers of camera sets: plain 3x4 P-matrix lists and Middlebury `*_par.txt`.
#include <Eigen/Core>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/rig.h"

namespace studio {
namespace {

struct Token {
  std::string text;
  int line = 0;
};

// Reads a whole text file; errors name the file.
Expected<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return fail(path + ": read error");
  return buffer.str();
}

// Strict, locale-independent number parsing of a whole token; non-finite numbers are rejected.
Expected<double> parse_number(const std::string& path, const Token& t) {
  double value = 0;
  const char* begin = t.text.data();
  const char* end = begin + t.text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end) {
    return fail(path + ":" + std::to_string(t.line) + ": expected a number, got '" + t.text + "'");
  }
  if (!std::isfinite(value)) {
    return fail(path + ":" + std::to_string(t.line) + ": non-finite number '" + t.text + "'");
  }
  return value;
}

std::string at(const std::string& path, int line) {
  return path + ":" + std::to_string(line) + ": ";
}

}  // namespace

Expected<Rig> import_projection_matrices(const std::string& path, int width, int height,
                                         std::string_view id_prefix) {
  Expected<std::string> text = read_text(path);
  if (!text) return std::unexpected(text.error());
  return parse_projection_matrices(*text, path, width, height, id_prefix);
}

Expected<Rig> parse_projection_matrices(std::string_view text, const std::string& path, int width,
                                        int height, std::string_view id_prefix) {
  if (width <= 0 || height <= 0) return fail(path + ": image size must be positive");
  std::vector<Token> tokens;
  int line = 1;
  std::string current;
  bool comment = false;
  auto flush = [&] {
    if (!current.empty()) tokens.push_back({std::move(current), line});
    current.clear();
  };
  for (char ch : text) {
    if (ch == '\n') {
      flush();
      ++line;
      comment = false;
    } else if (comment) {
    } else if (ch == '#') {
      flush();
      comment = true;
    } else if (std::isspace(static_cast<unsigned char>(ch)) || ch == ',' || ch == ';' ||
               ch == '[' || ch == ']') {
      flush();
    } else {
      current += ch;
    }
  }
  flush();
  if (tokens.empty()) return fail(path + ": no projection matrices (empty file)");
  if (tokens.size() % 12 != 0) {
    return fail(at(path, tokens.back().line) + "expected 12 numbers per camera, got " +
                std::to_string(tokens.size()) + " numbers in total");
  }
  Rig rig;
  for (size_t c = 0; c < tokens.size() / 12; ++c) {
    Eigen::Matrix<double, 3, 4> P;
    for (int i = 0; i < 12; ++i) {
      Expected<double> v = parse_number(path, tokens[c * 12 + i]);
      if (!v) return std::unexpected(v.error());
      P(i / 4, i % 4) = *v;
    }
    Expected<Camera> camera = camera_from_projection_matrix(P, width, height);
    if (!camera) {
      return fail(at(path, tokens[c * 12].line) + "camera " + std::to_string(c) + ": " +
                  camera.error().message);
    }
    camera->id = std::string(id_prefix) + std::to_string(c);
    rig.cameras.push_back(std::move(*camera));
  }
  return rig;
}

Expected<Rig> import_middlebury(const std::string& path, int width, int height) {
  Expected<std::string> text = read_text(path);
  if (!text) return std::unexpected(text.error());
  return parse_middlebury(*text, path, width, height);
}

Expected<Rig> parse_middlebury(std::string_view text, const std::string& path, int width,
                               int height) {
  if (width <= 0 || height <= 0) return fail(path + ": image size must be positive");
  std::istringstream in{std::string(text)};
  std::string row;
  int line = 0;
  long count = -1;
  Rig rig;
  while (std::getline(in, row)) {
    ++line;
    if (!row.empty() && row.back() == '\r') row.pop_back();
    std::istringstream fields(row);
    std::vector<Token> tokens;
    for (std::string f; fields >> f;) tokens.push_back({f, line});
    if (tokens.empty()) continue;
    if (count < 0) {
      Expected<double> n = parse_number(path, tokens[0]);
      if (!n || tokens.size() != 1 || *n != std::floor(*n) || *n < 1 || *n > 100000) {
        return fail(at(path, line) + "expected the camera count on the first line");
      }
      count = static_cast<long>(*n);
      continue;
    }
    if (static_cast<long>(rig.cameras.size()) == count) {
      return fail(at(path, line) + "more camera lines than the count " + std::to_string(count));
    }
    if (tokens.size() != 22) {
      return fail(at(path, line) + "expected a name and 21 numbers, got " +
                  std::to_string(tokens.size()) + " fields");
    }
    double v[21];
    for (int i = 0; i < 21; ++i) {
      Expected<double> x = parse_number(path, tokens[i + 1]);
      if (!x) return std::unexpected(x.error());
      v[i] = *x;
    }
    Eigen::Matrix3d K, R;
    K << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
    R << v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17];
    const Eigen::Vector3d t(v[18], v[19], v[20]);
    Expected<Intrinsics> k = intrinsics_from_matrix(K);
    if (!k) return fail(at(path, line) + "K: " + k.error().message);
    Expected<Rigid3> pose = rigid_from_matrix(R, t);
    if (!pose) return fail(at(path, line) + "R: " + pose.error().message);
    Camera camera;
    camera.id = tokens[0].text.substr(0, tokens[0].text.rfind('.'));
    if (camera.id.empty()) camera.id = tokens[0].text;
    camera.width = width;
    camera.height = height;
    camera.intrinsics = *k;
    camera.cam_from_world = *pose;
    if (rig.find_camera(camera.id) != nullptr) {
      return fail(at(path, line) + "duplicate camera '" + camera.id + "'");
    }
    rig.cameras.push_back(std::move(camera));
  }
  if (count < 0) return fail(path + ": empty file");
  if (static_cast<long>(rig.cameras.size()) != count) {
    return fail(at(path, line) + "expected " + std::to_string(count) + " cameras, got " +
                std::to_string(rig.cameras.size()));
  }
  return rig;
}

}  // namespace studio

// Planar calibration targets rendered into virtual cameras (sim/target.h).
#include "sim/target.h"

#include <algorithm>
#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <random>

#include "message.h"

namespace studio::sim {

Expected<void> TargetSpec::validate() const {
  if (squares_x < 3 || squares_y < 3 || squares_x > 100 || squares_y > 100) {
    return fail(detail::cat("target ", squares_x, "x", squares_y, " squares outside [3, 100]"));
  }
  if (!(square > 0.001 && square < 1)) return fail(detail::cat("target square ", square, " m outside (0.001, 1)"));
  if (!(margin >= 0 && margin < 1)) return fail(detail::cat("target margin ", margin, " m outside [0, 1)"));
  if (kind == Kind::charuco && !(marker > 0 && marker < square)) {
    return fail(detail::cat("ChArUco marker ", marker, " m must be positive and smaller than the square ", square, " m"));
  }
  if (kind == Kind::charuco && (dictionary < 0 || dictionary > 20)) {
    return fail(detail::cat("ChArUco dictionary ", dictionary, " outside cv::aruco's predefined [0, 20]"));
  }
  return {};
}

std::vector<Eigen::Vector3d> TargetSpec::corners() const {
  std::vector<Eigen::Vector3d> out;
  for (int j = 0; j + 1 < squares_y; ++j) {
    for (int i = 0; i + 1 < squares_x; ++i) out.emplace_back((i + 1) * square, (j + 1) * square, 0);
  }
  return out;
}

Expected<void> TargetRender::validate() const {
  if (supersample < 1 || supersample > 32) return fail(detail::cat("supersample ", supersample, " outside [1, 32]"));
  if (!(noise_sigma >= 0 && noise_sigma <= 40)) return fail("target noise_sigma outside [0, 40]");
  if (!(shading >= 0 && shading < 1)) return fail("target shading outside [0, 1)");
  return {};
}

Expected<Target> Target::create(const TargetSpec& spec) {
  if (auto ok = spec.validate(); !ok) return std::unexpected(ok.error());
  Target target;
  target.spec_ = spec;
  target.marker_of_square_.assign(static_cast<std::size_t>(spec.squares_x) * spec.squares_y, -1);
  if (spec.kind == TargetSpec::Kind::chessboard) return target;
  try {
    const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(spec.dictionary);
    const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
        spec.squares_x, spec.squares_y, static_cast<float>(spec.square),
        static_cast<float>(spec.marker), dict);
    if (static_cast<int>(board->ids.size()) > dict->bytesList.rows) {
      return fail(detail::cat("ChArUco board needs ", board->ids.size(), " markers but dictionary ", spec.dictionary, " has ", dict->bytesList.rows));
    }
    const int n = dict->markerSize;
    for (std::size_t m = 0; m < board->ids.size(); ++m) {
      const auto& c = board->objPoints[m];
      Marker marker;
      marker.id = board->ids[m];
      marker.origin = Eigen::Vector2d(c[0].x, c[0].y);
      marker.ex = Eigen::Vector2d(c[1].x - c[0].x, c[1].y - c[0].y);
      marker.ey = Eigen::Vector2d(c[3].x - c[0].x, c[3].y - c[0].y);
      marker.cells = n + 2;
      marker.white.assign(static_cast<std::size_t>(n + 2) * (n + 2), 0);
      const cv::Mat bits = cv::aruco::Dictionary::getBitsFromByteList(
          dict->bytesList.rowRange(marker.id, marker.id + 1), n);
      for (int r = 0; r < n; ++r) {
        for (int q = 0; q < n; ++q) {
          marker.white[static_cast<std::size_t>(r + 1) * (n + 2) + q + 1] = bits.at<uint8_t>(r, q) ? 1 : 0;
        }
      }
      const Eigen::Vector2d centre = marker.origin + 0.5 * (marker.ex + marker.ey);
      const int i = static_cast<int>(std::floor(centre.x() / spec.square));
      const int j = static_cast<int>(std::floor(centre.y() / spec.square));
      if (i < 0 || j < 0 || i >= spec.squares_x || j >= spec.squares_y) {
        return fail("ChArUco layout from cv::aruco places a marker off the board");
      }
      target.marker_of_square_[static_cast<std::size_t>(j) * spec.squares_x + i] =
          static_cast<int>(target.markers_.size());
      target.markers_.push_back(std::move(marker));
    }
  } catch (const cv::Exception& e) {
    return fail(detail::cat("ChArUco dictionary ", spec.dictionary, ": ", e.what()));
  }
  return target;
}

int Target::ink(double x, double y) const {
  const double s = spec_.square, m = spec_.margin;
  const double w = spec_.squares_x * s, h = spec_.squares_y * s;
  if (!(x >= -m && y >= -m && x < w + m && y < h + m)) return -1;
  if (x < 0 || y < 0 || x >= w || y >= h) return 1;
  const int i = std::min(static_cast<int>(x / s), spec_.squares_x - 1);
  const int j = std::min(static_cast<int>(y / s), spec_.squares_y - 1);
  if (spec_.kind == TargetSpec::Kind::chessboard) return (i + j) % 2 == 0 ? 0 : 1;
  const int mi = marker_of_square_[static_cast<std::size_t>(j) * spec_.squares_x + i];
  if (mi < 0) return 0;  // ChArUco: squares without a marker are the black ones
  const Marker& mk = markers_[mi];
  const Eigen::Vector2d p = Eigen::Vector2d(x, y) - mk.origin;
  const double a = p.dot(mk.ex) / mk.ex.squaredNorm(), b = p.dot(mk.ey) / mk.ey.squaredNorm();
  if (a < 0 || b < 0 || a >= 1 || b >= 1) return 1;
  const int col = std::min(static_cast<int>(a * mk.cells), mk.cells - 1);
  const int row = std::min(static_cast<int>(b * mk.cells), mk.cells - 1);
  return mk.white[static_cast<std::size_t>(row) * mk.cells + col];
}

namespace {

// Maps observed pixels to points on the target plane (target frame), or NaN.
struct PlaneMapper {
  const Camera& camera;
  Eigen::Matrix3d R_tc;  // target_from_cam rotation
  Eigen::Vector3d C_t;   // camera centre in the target frame
  bool pinhole;

  PlaneMapper(const Camera& cam, const Rigid3& world_from_target)
      : camera(cam), pinhole(cam.distortion.is_identity()) {
    const Rigid3 target_from_cam = (cam.cam_from_world * world_from_target).inverse();
    R_tc = target_from_cam.R();
    C_t = target_from_cam.translation;
  }
  Eigen::Vector2d operator()(double u, double v) const {
    const auto& k = camera.intrinsics;
    const double y = (v - k.cy) / k.fy;
    Eigen::Vector2d n((u - k.cx - k.skew * y) / k.fx, y);
    if (!pinhole) n = undistort(camera.distortion, n);
    const Eigen::Vector3d d = R_tc * Eigen::Vector3d(n.x(), n.y(), 1.0);
    const double t = -C_t.z() / d.z();
    if (!(t > 0) || !std::isfinite(t)) return {NAN, NAN};
    return {C_t.x() + t * d.x(), C_t.y() + t * d.y()};
  }
};

}  // namespace

void Target::render(const Camera& camera, const Rigid3& world_from_target,
                    const TargetRender& o, Image<Rgb8>* image) const {
  if (auto ok = o.validate(); !ok) throw std::invalid_argument(ok.error().message);
  const int W = camera.width, H = camera.height;
  *image = Image<Rgb8>(W, H);
  const PlaneMapper map(camera, world_from_target);
  const bool front = map.C_t.z() < 0;
  const double board_w = spec_.squares_x * spec_.square, board_h = spec_.squares_y * spec_.square;
  // Colour (float RGB) of a plane point.
  const float bg[3] = {o.blue_background ? 30.f : 128.f, o.blue_background ? 66.f : 128.f,
                       o.blue_background ? 212.f : 128.f};
  auto colour = [&](const Eigen::Vector2d& p, float* out) {
    const int k = std::isnan(p.x()) ? -1 : ink(p.x(), p.y());
    if (k < 0) {
      std::copy_n(bg, 3, out);
      return;
    }
    if (!front) {
      out[0] = out[1] = out[2] = 90.f;
      return;
    }
    const double gradient = 1 - o.shading * (0.5 * p.x() / board_w + 0.5 * p.y() / board_h);
    const float v = static_cast<float>((k ? o.white : o.black) * gradient);
    out[0] = v;
    out[1] = v;
    out[2] = static_cast<float>(v * 0.98);
  };
  // Plane points of the pixel corners (u - 0.5, v - 0.5), shared between neighbours.
  std::vector<Eigen::Vector2d> grid(static_cast<std::size_t>(W + 1) * (H + 1));
  std::vector<int8_t> grid_ink(grid.size());
  for (int v = 0; v <= H; ++v) {
    for (int u = 0; u <= W; ++u) {
      const Eigen::Vector2d p = map(u - 0.5, v - 0.5);
      grid[static_cast<std::size_t>(v) * (W + 1) + u] = p;
      grid_ink[static_cast<std::size_t>(v) * (W + 1) + u] =
          static_cast<int8_t>(std::isnan(p.x()) ? -1 : ink(p.x(), p.y()));
    }
  }
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(o.noise_sigma));
  const int n = o.supersample;
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t g = static_cast<std::size_t>(v) * (W + 1) + u;
      const int8_t k0 = grid_ink[g];
      const Eigen::Vector2d centre = map(u, v);
      const int kc = std::isnan(centre.x()) ? -1 : ink(centre.x(), centre.y());
      const bool uniform = grid_ink[g + 1] == k0 && grid_ink[g + W + 1] == k0 &&
                           grid_ink[g + W + 2] == k0 && kc == k0;
      float c[3] = {0, 0, 0};
      if (uniform || n == 1) {
        colour(centre, c);
      } else {
        float s[3];
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) {
            colour(map(u - 0.5 + (i + 0.5) / n, v - 0.5 + (j + 0.5) / n), s);
            for (int q = 0; q < 3; ++q) c[q] += s[q];
          }
        }
        for (float& q : c) q /= static_cast<float>(n * n);
      }
      auto quant = [&](float x) {
        if (o.noise_sigma > 0) x += noise(rng);
        return static_cast<uint8_t>(std::clamp(x + 0.5f, 0.0f, 255.0f));
      };
      (*image)(u, v) = {quant(c[0]), quant(c[1]), quant(c[2])};
    }
  }
}

void Target::project_corners(const Camera& camera, const Rigid3& world_from_target,
                             std::vector<Eigen::Vector2d>* pixels,
                             std::vector<bool>* visible) const {
  const std::vector<Eigen::Vector3d> corners = spec_.corners();
  const Rigid3 target_from_cam = (camera.cam_from_world * world_from_target).inverse();
  const bool front = target_from_cam.translation.z() < 0;
  pixels->assign(corners.size(), Eigen::Vector2d::Zero());
  visible->assign(corners.size(), false);
  for (std::size_t i = 0; i < corners.size(); ++i) {
    Eigen::Vector2d px;
    if (camera.project(world_from_target * corners[i], &px)) {
      (*pixels)[i] = px;
      (*visible)[i] = front && camera.in_image(px);
    }
  }
}

}  // namespace studio::sim

#include "capture/take_calibration.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace studio::capture {

std::string format_calibration_line(uint64_t frame, const Camera& camera) {
  const Distortion& d = camera.distortion;
  int model = 0;
  double k[5] = {0, 0, 0, 0, 0};
  if (d.model == Distortion::Model::radial) {
    model = 1;
    k[0] = d.rd3;
    k[1] = d.rd5;
  } else if (d.model == Distortion::Model::opencv) {
    model = 2;
    k[0] = d.k1, k[1] = d.k2, k[2] = d.p1, k[3] = d.p2, k[4] = d.k3;
  }
  const Intrinsics& in = camera.intrinsics;
  const Eigen::Matrix3d R = camera.cam_from_world.R();
  const Eigen::Vector3d& t = camera.cam_from_world.translation;
  std::string line = std::to_string(frame) + " " + std::to_string(model);
  char buf[32];
  auto add = [&](double v) {
    std::snprintf(buf, sizeof buf, " %.17g", v);
    line += buf;
  };
  for (double v : {in.fx, in.fy, in.cx, in.cy, in.skew}) add(v);
  for (double v : k) add(v);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) add(R(r, c));
  for (int i = 0; i < 3; ++i) add(t[i]);
  return line + "\n";
}

Expected<std::map<uint64_t, Camera>> read_take_calibration(const std::string& take_dir,
                                                           const Camera& base) {
  std::map<uint64_t, Camera> cameras;
  const std::string path = take_dir + "/" + kCalibrationFile;
  if (!std::filesystem::exists(path)) return cameras;
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot open");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) break;  // torn last line
    ++line_no;
    std::istringstream line(text.substr(pos, end - pos));
    pos = end + 1;
    uint64_t frame = 0;
    int model = -1;
    double v[22];
    line >> frame >> model;
    for (double& x : v) line >> x;
    std::string rest;
    if (!line || (line >> rest) || model < 0 || model > 2)
      return fail(path + ":" + std::to_string(line_no) + ": malformed calibration line");
    for (double x : v)
      if (!std::isfinite(x))
        return fail(path + ":" + std::to_string(line_no) + ": non-finite value");
    Camera c = base;
    c.intrinsics = {v[0], v[1], v[2], v[3], v[4]};
    c.distortion = model == 1   ? Distortion::radial(v[5], v[6])
                   : model == 2 ? Distortion::opencv(v[5], v[6], v[7], v[8], v[9])
                                : Distortion::none();
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) R(r, k) = v[10 + 3 * r + k];
    c.cam_from_world = Rigid3(R, Eigen::Vector3d(v[19], v[20], v[21]));
    cameras[frame] = std::move(c);
  }
  return cameras;
}

}  // namespace studio::capture

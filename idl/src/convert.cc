#include "wire/convert.h"

#include <cmath>
#include <span>
#include <string>

#include "wire/sample.h"

namespace studio::wire {

Expected<RunMask> to_core(const studio_AlphaMask& s, RunMask reuse) {
  if (s.encoding == studio_MASK_CODEC) {
    auto bytes = view(s.data);
    auto mask = decode_mask(std::span<const uint8_t>(bytes.data(), bytes.size()), std::move(reuse));
    if (!mask) return mask;
    if (mask->width() != int(s.width) || mask->height() != int(s.height))
      return fail("mask " + std::string(s.camera_id) + ": codec size " + std::to_string(mask->width()) + "x" +
                  std::to_string(mask->height()) + " differs from the sample's " + std::to_string(s.width) +
                  "x" + std::to_string(s.height));
    return mask;
  }
  if (s.encoding != studio_MASK_RUNS) return fail("mask " + std::string(s.camera_id) + ": unknown encoding");
  const auto row_start = view(s.row_start);
  const auto runs = view(s.runs);
  if (row_start.size() != std::size_t(s.height) + 1 || runs.size() != std::size_t(row_start.back()) * 2)
    return fail("mask " + std::string(s.camera_id) + ": run table inconsistent with its height");
  RunMask out = (reuse.width() == int(s.width) && reuse.height() == int(s.height)) ? std::move(reuse)
                                                                                 : RunMask(int(s.width), int(s.height));
  out.clear();
  for (uint32_t y = 0; y < s.height; ++y)
    for (uint32_t r = row_start[y]; r < row_start[y + 1]; ++r) out.push_run(int(y), int32_t(runs[2 * r]), int32_t(runs[2 * r + 1]));
  out.finish();
  if (!out.valid()) return fail("mask " + std::string(s.camera_id) + ": runs unsorted or outside the image");
  return out;
}

void from_core(const RunMask& mask, studio_MaskEncoding encoding, studio_AlphaMask& s) {
  s.width = uint32_t(mask.width());
  s.height = uint32_t(mask.height());
  s.encoding = encoding;
  if (encoding == studio_MASK_CODEC) {
    const std::vector<uint8_t> bytes = encode_mask(mask);
    assign(s.data, bytes);
    resize(s.row_start, 0);
    resize(s.runs, 0);
    return;
  }
  assign(s.row_start, mask.row_start());
  std::vector<uint32_t> runs;
  runs.reserve(mask.runs().size() * 2);
  for (const Run& r : mask.runs()) {
    runs.push_back(uint32_t(r.begin));
    runs.push_back(uint32_t(r.end));
  }
  assign(s.runs, runs);
  resize(s.data, 0);
}

Expected<Camera> to_core(const studio_CameraCalibration& s) {
  Camera c;
  c.id = s.camera_id;
  c.width = int(s.width);
  c.height = int(s.height);
  Eigen::Matrix3d K, R;
  for (int i = 0; i < 9; ++i) {
    K(i / 3, i % 3) = s.K[i];
    R(i / 3, i % 3) = s.R[i];
  }
  if (!K.allFinite() || !R.allFinite() || std::abs(K(2, 2)) < 1e-12)
    return fail("calibration " + c.id + ": K or R not finite");
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0)
    return fail("calibration " + c.id + ": R is not a rotation");
  c.intrinsics = Intrinsics::from_K(K);
  if (c.intrinsics.fx <= 0 || c.intrinsics.fy <= 0) return fail("calibration " + c.id + ": focal length <= 0");
  c.distortion = (s.rd3 == 0 && s.rd5 == 0) ? Distortion::none() : Distortion::radial(s.rd3, s.rd5);
  c.cam_from_world = Rigid3(R, Eigen::Vector3d(s.t[0], s.t[1], s.t[2]));
  return c;
}

Expected<bool> from_core(const Camera& c, studio_CameraCalibration& s) {
  if (c.distortion.model == Distortion::Model::opencv)
    return fail("camera " + c.id + ": OpenCV distortion cannot travel on studio/camera/calibration; "
                "convert it explicitly with to_paper_model (core/distortion_fit.h)");
  set(s.camera_id, c.id);
  s.width = uint32_t(c.width);
  s.height = uint32_t(c.height);
  const Eigen::Matrix3d K = c.intrinsics.K();
  const Eigen::Matrix3d R = c.cam_from_world.R();
  for (int i = 0; i < 9; ++i) {
    s.K[i] = K(i / 3, i % 3);
    s.R[i] = R(i / 3, i % 3);
  }
  for (int i = 0; i < 3; ++i) s.t[i] = c.cam_from_world.translation[i];
  s.rd3 = c.distortion.model == Distortion::Model::radial ? c.distortion.rd3 : 0;
  s.rd5 = c.distortion.model == Distortion::Model::radial ? c.distortion.rd5 : 0;
  return true;
}

Expected<void> from_core(const Projector& p, const Eigen::Matrix3d& pixel_from_screen,
                         studio_ProjectorCalibration& s) {
  const Camera& c = p.camera;
  if (c.distortion.model != Distortion::Model::none)
    return fail("projector " + c.id + ": lens distortion cannot travel on studio/projector/calibration");
  if (!pixel_from_screen.allFinite() || std::abs(pixel_from_screen(2, 2)) < 1e-15)
    return fail("projector " + c.id + ": homography not finite or h[8] = 0");
  set(s.projector_id, c.id);
  s.width = uint32_t(c.width);
  s.height = uint32_t(c.height);
  const Eigen::Matrix3d K = c.intrinsics.K();
  const Eigen::Matrix3d R = c.cam_from_world.R();
  const Eigen::Matrix3d H = pixel_from_screen / pixel_from_screen(2, 2);
  for (int i = 0; i < 9; ++i) {
    s.K[i] = K(i / 3, i % 3);
    s.R[i] = R(i / 3, i % 3);
    s.homography[i] = H(i / 3, i % 3);
  }
  for (int i = 0; i < 3; ++i) s.t[i] = c.cam_from_world.translation[i];
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 3; ++i) s.screen_corners[3 * k + i] = p.screen[std::size_t(k)][i];
  return {};
}

Expected<Projector> to_core(const studio_ProjectorCalibration& s) {
  studio_CameraCalibration c{};
  set(c.camera_id, std::string(s.projector_id));
  c.width = s.width;
  c.height = s.height;
  for (int i = 0; i < 9; ++i) {
    c.K[i] = s.K[i];
    c.R[i] = s.R[i];
  }
  for (int i = 0; i < 3; ++i) c.t[i] = s.t[i];
  auto camera = to_core(c);
  if (!camera) return std::unexpected(camera.error());
  Projector p;
  p.camera = std::move(*camera);
  for (int k = 0; k < 4; ++k)
    p.screen[std::size_t(k)] = Eigen::Vector3d(s.screen_corners[3 * k], s.screen_corners[3 * k + 1],
                                               s.screen_corners[3 * k + 2]);
  return p;
}

// The run table of studio/projector/mask and studio/projector/frame (row y's runs are
// runs[2*row_start[y] .. 2*row_start[y+1]), begin/end pairs) ↔ RunMask.
namespace {

Expected<RunMask> mask_from_runs(const std::string& what, uint32_t width, uint32_t height,
                                 std::span<const uint32_t> row_start, std::span<const uint32_t> runs) {
  if (row_start.size() != std::size_t(height) + 1 || runs.size() != std::size_t(row_start.back()) * 2)
    return fail(what + ": run table inconsistent with its height");
  RunMask out(static_cast<int>(width), static_cast<int>(height));
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t r = row_start[y]; r < row_start[y + 1]; ++r)
      out.push_run(int(y), int32_t(runs[2 * r]), int32_t(runs[2 * r + 1]));
  out.finish();
  if (!out.valid()) return fail(what + ": runs unsorted or outside the image");
  return out;
}

std::vector<uint32_t> run_pairs(const RunMask& mask) {
  std::vector<uint32_t> runs;
  runs.reserve(mask.runs().size() * 2);
  for (const Run& r : mask.runs()) {
    runs.push_back(uint32_t(r.begin));
    runs.push_back(uint32_t(r.end));
  }
  return runs;
}

}  // namespace

Expected<RunMask> to_core(const studio_ProjectorMask& s) {
  return mask_from_runs("projector mask " + std::string(s.projector_id), s.width, s.height,
                        view(s.row_start), view(s.runs));
}

void from_core(const RunMask& mask, studio_ProjectorMask& s) {
  s.width = uint32_t(mask.width());
  s.height = uint32_t(mask.height());
  assign(s.row_start, mask.row_start());
  assign(s.runs, run_pairs(mask));
}

void from_core(const RunMask& mask, studio_ProjectorFrame& s) {
  s.width = uint32_t(mask.width());
  s.height = uint32_t(mask.height());
  assign(s.mask_row_start, mask.row_start());
  assign(s.mask_runs, run_pairs(mask));
}

Expected<RunMask> to_core(const studio_ProjectorFrame& s) {
  return mask_from_runs("projector frame " + std::string(s.projector_id), s.width, s.height,
                        view(s.mask_row_start), view(s.mask_runs));
}

}  // namespace studio::wire

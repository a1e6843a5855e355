#include "support/middlebury_dino.h"

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/rig.h"

namespace studio::testing {

Eigen::Vector3d DinoViews::box_min(double pad) {
  return Eigen::Vector3d(-0.061897, -0.018874, -0.057845) - Eigen::Vector3d::Constant(pad);
}
Eigen::Vector3d DinoViews::box_max(double pad) {
  return Eigen::Vector3d(0.010897, 0.068227, 0.015495) + Eigen::Vector3d::Constant(pad);
}

Expected<DinoViews> load_middlebury_dino(const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path d(dir);
  auto rig = import_middlebury((d / "dinoSR_par.txt").string(), 640, 480);
  if (!rig) return std::unexpected(rig.error());
  std::ifstream list(d / "dinoSR_good_silhouette_images.txt");
  if (!list) return fail(dir + ": no dinoSR_good_silhouette_images.txt");
  DinoViews v;
  const cv::Mat dilate = cv::getStructuringElement(cv::MORPH_ELLIPSE, {21, 21});
  const cv::Mat erode = cv::getStructuringElement(cv::MORPH_ELLIPSE, {15, 15});
  for (std::string name; list >> name;) {
    if (name.size() <= 4 || !name.ends_with(".png")) continue;
    const std::string id = name.substr(0, name.size() - 4);
    const Camera* c = rig->find_camera(id);
    if (!c) return fail(dir + ": no camera " + id + " in dinoSR_par.txt");
    const cv::Mat bgr = cv::imread((d / name).string(), cv::IMREAD_COLOR);
    if (bgr.empty()) return fail(dir + ": cannot read " + name);
    std::vector<cv::Mat> ch;
    cv::split(bgr, ch);
    cv::Mat m = cv::max(cv::max(ch[0], ch[1]), ch[2]) > int(0.19 * 255);
    cv::dilate(m, m, dilate);
    cv::erode(m, m, erode);
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    v.cameras.push_back(*c);
    v.rgb.push_back(rgb);
    v.masks.push_back(
        RunMask::from_mask(MaskView(m.ptr<uint8_t>(), m.cols, m.rows, std::ptrdiff_t(m.step))));
    v.silhouettes.push_back(std::move(m));
  }
  if (v.cameras.size() < 10) return fail(dir + ": fewer than 10 usable views");
  return v;
}

}  // namespace studio::testing

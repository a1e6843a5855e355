#include "keyer/config/image_io.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace studio::keyer {

Expected<Image<Rgb8>> read_rgb(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail("cannot read image '" + path + "': no such file");
  cv::Mat m;
  try {
    m = cv::imread(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    m.release();
  }
  if (m.empty() || m.type() != CV_8UC3)
    return fail("cannot read image '" + path + "': not a decodable PNG/JPEG image");
  Image<Rgb8> out(m.cols, m.rows);
  cv::Mat dst(m.rows, m.cols, CV_8UC3, out.data());
  cv::cvtColor(m, dst, cv::COLOR_BGR2RGB);
  return out;
}

Expected<void> write_mask_png(const std::string& path, const Mask& mask) {
  const cv::Mat m(mask.height(), mask.width(), CV_8UC1, const_cast<uint8_t*>(mask.data()));
  bool ok = false;
  try {
    ok = cv::imwrite(path, m);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return fail("cannot write '" + path + "'");
  return {};
}

Expected<void> write_rgb_png(const std::string& path, const Image<Rgb8>& image) {
  const cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<Rgb8*>(image.data()));
  const std::string tmp = path + ".part.png";  // OpenCV picks the format by the extension
  bool ok = false;
  try {
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    ok = cv::imwrite(tmp, bgr);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    return fail("cannot write '" + path + "'");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return fail("cannot write '" + path + "': rename failed");
  }
  return {};
}

}  // namespace studio::keyer

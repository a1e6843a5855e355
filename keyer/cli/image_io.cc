#include "image_io.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace studio::keyer {

Expected<Image<Rgb8>> read_rgb(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail("cannot read image '" + path + "': no such file");
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

}  // namespace studio::keyer

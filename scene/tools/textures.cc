#include "textures.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace studio::scene_tools {
namespace {

// Fractal value noise in [0, 1]: random lattices at doubling resolutions, upsampled and summed.
cv::Mat fractal_noise(int size, std::uint64_t seed, int octaves) {
  cv::RNG rng(seed);
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32F);
  float amplitude = 1, total = 0;
  for (int o = 0; o < octaves; ++o) {
    const int cells = 4 << o;
    cv::Mat small(cells, cells, CV_32F);
    rng.fill(small, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat big;
    cv::resize(small, big, cv::Size(size, size), 0, 0, cv::INTER_CUBIC);
    sum += amplitude * big;
    total += amplitude;
    amplitude *= 0.5f;
  }
  return sum / total;
}

std::vector<std::uint8_t> png(const cv::Mat& bgr) {
  std::vector<std::uint8_t> out;
  if (!cv::imencode(".png", bgr, out)) throw std::runtime_error("PNG encoding failed");
  return out;
}

}  // namespace

std::vector<std::uint8_t> marble_png(int size) {
  const cv::Mat n = fractal_noise(size, 11, 6);
  cv::Mat img(size, size, CV_8UC3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float t = static_cast<float>(x + y) / size;
      const float vein = std::pow(std::abs(std::sin(3.14159f * (3 * t + 4 * n.at<float>(y, x)))), 0.35f);
      const float base = 200 + 45 * vein;
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(base - 6),
                                          cv::saturate_cast<uchar>(base - 3),
                                          cv::saturate_cast<uchar>(base));
    }
  // Tile joints every quarter.
  for (int k = 0; k <= 4; ++k) {
    const int p = std::min(k * size / 4, size - 1);
    cv::line(img, {p, 0}, {p, size - 1}, cv::Scalar(150, 150, 155), 2);
    cv::line(img, {0, p}, {size - 1, p}, cv::Scalar(150, 150, 155), 2);
  }
  return png(img);
}

std::vector<std::uint8_t> wall_panel_png(int size) {
  const cv::Mat n = fractal_noise(size, 23, 5);
  cv::Mat img(size, size, CV_8UC3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float v = 0.93f + 0.07f * n.at<float>(y, x);
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(150 * v),
                                          cv::saturate_cast<uchar>(180 * v),
                                          cv::saturate_cast<uchar>(200 * v));
    }
  const int m = size / 10;
  cv::rectangle(img, {m, m}, {size - m, size - m}, cv::Scalar(110, 135, 155), 6);
  cv::rectangle(img, {2 * m, 2 * m}, {size - 2 * m, size - 2 * m}, cv::Scalar(125, 150, 170), 3);
  cv::line(img, {0, size - 4}, {size - 1, size - 4}, cv::Scalar(80, 95, 110), 8);
  return png(img);
}

std::vector<std::uint8_t> stone_png(int size) {
  const cv::Mat n = fractal_noise(size, 37, 7);
  cv::RNG rng(41);
  cv::Mat img(size, size, CV_8UC3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float g = 95 + 60 * n.at<float>(y, x) + static_cast<float>(rng.gaussian(10));
      img.at<cv::Vec3b>(y, x) = cv::Vec3b::all(cv::saturate_cast<uchar>(g));
    }
  return png(img);
}

std::vector<std::uint8_t> landscape_png(int w, int h) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    const float t = static_cast<float>(y) / h;
    img.row(y).setTo(cv::Scalar(200 - 60 * t, 180 - 40 * t, 150 - 30 * t));
  }
  cv::circle(img, {w * 3 / 4, h / 4}, h / 10, cv::Scalar(150, 200, 230), cv::FILLED, cv::LINE_AA);
  std::vector<cv::Point> far{{0, h * 6 / 10}, {w / 4, h * 45 / 100}, {w / 2, h * 55 / 100},
                             {w * 3 / 4, h * 4 / 10}, {w, h * 55 / 100}, {w, h}, {0, h}};
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{far}, cv::Scalar(120, 135, 125), cv::LINE_AA);
  std::vector<cv::Point> near{{0, h * 8 / 10}, {w / 3, h * 7 / 10}, {w * 2 / 3, h * 78 / 100},
                              {w, h * 7 / 10}, {w, h}, {0, h}};
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{near}, cv::Scalar(80, 110, 105), cv::LINE_AA);
  cv::rectangle(img, {0, 0}, {w - 1, h - 1}, cv::Scalar(40, 70, 110), h / 20);  // gilt frame
  return png(img);
}

std::vector<std::uint8_t> abstract_png(int w, int h) {
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(200, 205, 210));
  cv::RNG rng(53);
  for (int i = 0; i < 14; ++i) {
    const cv::Point a(rng.uniform(0, w), rng.uniform(0, h));
    const cv::Point b(a.x + rng.uniform(20, w / 3), a.y + rng.uniform(20, h / 3));
    const cv::Scalar c(rng.uniform(90, 170), rng.uniform(90, 150), rng.uniform(100, 160));
    cv::rectangle(img, a, b, c, cv::FILLED);
    cv::rectangle(img, a, b, cv::Scalar(40, 40, 40), 4);
  }
  cv::rectangle(img, {0, 0}, {w - 1, h - 1}, cv::Scalar(40, 70, 110), h / 20);
  return png(img);
}

}  // namespace studio::scene_tools

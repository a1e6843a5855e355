// Pixel formats of GenICam cameras and their conversion to RGB8 (declared in
// capture/aravis_source.h; kept apart from the Aravis session code).
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/aravis_source.h"

namespace studio::capture {
namespace {

struct FormatInfo {
  CameraPixelFormat format;
  const char* name;
  int cv_code;  // OpenCV demosaic code, -1 when not Bayer
};
// OpenCV names a Bayer pattern by the second row's second and third pixels, GenICam by the first
// row's first two: GenICam BayerRG8 (R G / G B) is OpenCV's BayerBG.
constexpr FormatInfo kFormats[] = {
    {CameraPixelFormat::mono8, "Mono8", -1},
    {CameraPixelFormat::rgb8, "RGB8", -1},
    {CameraPixelFormat::bayer_rg8, "BayerRG8", cv::COLOR_BayerBG2RGB},
    {CameraPixelFormat::bayer_gr8, "BayerGR8", cv::COLOR_BayerGB2RGB},
    {CameraPixelFormat::bayer_gb8, "BayerGB8", cv::COLOR_BayerGR2RGB},
    {CameraPixelFormat::bayer_bg8, "BayerBG8", cv::COLOR_BayerRG2RGB},
};

const FormatInfo* find_format(CameraPixelFormat format) {
  for (const FormatInfo& f : kFormats) {
    if (f.format == format) return &f;
  }
  return nullptr;
}

}  // namespace

Expected<CameraPixelFormat> parse_pixel_format(std::string_view name) {
  if (name.empty() || name == "keep") return CameraPixelFormat::keep;
  for (const FormatInfo& f : kFormats) {
    if (name == f.name) return f.format;
  }
  return fail("pixel format '" + std::string(name) +
              "' is not one of Mono8, RGB8, BayerRG8, BayerGR8, BayerGB8, BayerBG8");
}

const char* genicam_name(CameraPixelFormat format) {
  const FormatInfo* f = find_format(format);
  return f ? f->name : "keep";
}

Expected<Image<Rgb8>> convert_to_rgb(CameraPixelFormat format, std::span<const uint8_t> data,
                                     int width, int height) {
  const FormatInfo* info = find_format(format);
  if (!info) return fail("convert_to_rgb: no pixel format given");
  if (width <= 0 || height <= 0 || width > 65535 || height > 65535) {
    return fail("convert_to_rgb: bad image size " + std::to_string(width) + "x" +
                std::to_string(height));
  }
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  const std::size_t needed = format == CameraPixelFormat::rgb8 ? 3 * pixels : pixels;
  if (data.size() < needed) {
    return fail(std::string(info->name) + " " + std::to_string(width) + "x" +
                std::to_string(height) + " needs " + std::to_string(needed) + " bytes, got " +
                std::to_string(data.size()));
  }
  Image<Rgb8> image(width, height);
  cv::Mat out(height, width, CV_8UC3, image.data());
  if (format == CameraPixelFormat::rgb8) {
    std::memcpy(image.data(), data.data(), needed);
  } else {
    const cv::Mat in(height, width, CV_8UC1, const_cast<uint8_t*>(data.data()));
    if (format == CameraPixelFormat::mono8) {
      cv::cvtColor(in, out, cv::COLOR_GRAY2RGB);
    } else {
      if (width < 2 || height < 2) return fail("Bayer image smaller than 2x2");
      cv::cvtColor(in, out, info->cv_code);
    }
  }
  return image;
}

}  // namespace studio::capture

// Real images: the Middlebury dino views (../shared/data/middlebury_dino, black background) keyed
// by the difference key against a black clean plate; their masks through the codec.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/mask_codec.h"
#include "keyer/keyer.h"
#include "support/masks.h"

namespace fs = std::filesystem;

namespace studio::keyer {
namespace {

std::vector<Image<Rgb8>> dino_views() {
  std::vector<Image<Rgb8>> out;
  const fs::path dir = fs::path(STUDIO_SHARED_DATA) / "middlebury_dino";
  for (int i = 1; i <= 16; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "dinoSR%04d.png", i);
    cv::Mat bgr = cv::imread((dir / name).string(), cv::IMREAD_COLOR);
    if (bgr.empty()) return {};
    Image<Rgb8> im(bgr.cols, bgr.rows);
    cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, im.data());
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    out.push_back(std::move(im));
  }
  return out;
}

// Middlebury's recipe (README of the data): threshold, then close (dilate 10, erode 7).
Mask recipe_mask(const Image<Rgb8>& im) {
  cv::Mat rgb(im.height(), im.width(), CV_8UC3, const_cast<Rgb8*>(im.data()));
  cv::Mat grey, m;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  cv::threshold(grey, m, 0.19 * 255, 255, cv::THRESH_BINARY);
  cv::dilate(m, m, cv::getStructuringElement(cv::MORPH_ELLIPSE, {21, 21}));
  cv::erode(m, m, cv::getStructuringElement(cv::MORPH_ELLIPSE, {15, 15}));
  Mask out(im.width(), im.height());
  std::copy(m.datastart, m.dataend, out.data());
  return out;
}

TEST(KeyerDataset, DinoMasksDifferenceKeyAndCodec) {
  const auto views = dino_views();
  if (views.empty()) GTEST_SKIP() << "../shared/data/middlebury_dino not found";
  KeyerOptions o;
  o.mode = KeyMode::kDifference;
  o.diff_low = 20;
  o.diff_high = 40;
  o.cleanup = {200, 3000};
  // A black background: the dino's dark parts match the plate, so a hole showing "clean
  // backing" is not evidence of a real gap here; fill holes by area only.
  o.cleanup.keep_backing_gaps = false;
  auto keyer = Keyer::create(o);
  ASSERT_TRUE(keyer);
  // Clean plate: the studio's black background.
  ASSERT_TRUE(keyer->capture_plate(Image<Rgb8>(views[0].width(), views[0].height(), Rgb8{0, 0, 0}).view()));
  RunMask mask;
  double bytes_delta = 0, bytes_runs = 0, iou_sum = 0;
  for (const auto& im : views) {
    ASSERT_TRUE(keyer->key(im.view(), mask));
    const auto delta = encode_mask(mask, MaskCoding::kRowDelta);
    const auto runs = encode_mask(mask, MaskCoding::kRuns);
    ASSERT_EQ(*decode_mask(delta), mask);
    ASSERT_EQ(*decode_mask(runs), mask);
    bytes_delta += delta.size();
    bytes_runs += runs.size();
    // Agreement with Middlebury's own silhouette recipe.
    const Mask ours = mask.to_mask(), theirs = recipe_mask(im);
    iou_sum += support::iou(ours, theirs);
  }
  const double n = double(views.size());
  std::printf("dino masks 640x480: mean %.0f bytes row-delta, %.0f bytes plain runs; IoU vs recipe %.4f\n",
              bytes_delta / n, bytes_runs / n, iou_sum / n);
  EXPECT_GT(iou_sum / n, 0.95);
  EXPECT_LT(bytes_delta / n, 1500);
  EXPECT_LT(bytes_delta, bytes_runs);
}

}  // namespace
}  // namespace studio::keyer

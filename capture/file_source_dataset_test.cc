// File replay of real data: the Middlebury dino folder (16 views), pixel-exact against OpenCV's
// decode, frame numbers consecutive across a loop. Label `dataset`; skips without the data.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "capture/file_source.h"

namespace studio::capture {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

Frame next_frame(FrameSource& source) {
  auto f = source.next(milliseconds(2000));
  EXPECT_TRUE(f) << (f ? "" : f.error().message);
  EXPECT_TRUE(f && *f);
  return f && *f ? std::move(**f) : Frame{};
}

TEST(FileSourceDataset, ReplaysMiddleburyDino) {
  const std::string folder = std::string(STUDIO_SHARED_DATA) + "/middlebury_dino";
  if (!fs::is_directory(folder)) GTEST_SKIP() << "real data absent: " << folder;
  FileSourceOptions o;
  o.id = "dino";
  o.path = folder;
  o.paced = false;
  o.loop = true;
  auto source = FileSource::create(o);
  ASSERT_TRUE(source) << source.error().message;
  ASSERT_EQ((*source)->size(), 16u);
  ASSERT_TRUE((*source)->start());
  const auto files = list_image_files(folder).value();
  uint64_t first_frame = 0;
  for (int i = 0; i < 17; ++i) {  // one full pass and the first frame of the next
    Frame f = next_frame(**source);
    if (i == 0) first_frame = f.frame;
    EXPECT_EQ(f.frame, first_frame + i);
    const cv::Mat bgr = cv::imread(files[i % 16], cv::IMREAD_COLOR);
    ASSERT_EQ(f.image.width(), bgr.cols);
    ASSERT_EQ(f.image.height(), bgr.rows);
    // Every pixel equals OpenCV's decode, channels swapped to RGB.
    int mismatches = 0;
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
        mismatches += !(f.image(x, y) == Rgb8{p[2], p[1], p[0]});
      }
    }
    EXPECT_EQ(mismatches, 0) << files[i % 16];
  }
  EXPECT_EQ(fs::path(files[0]).filename(), "dinoSR0001.png");
  EXPECT_EQ((*source)->stats().frames, 17u);
  EXPECT_EQ((*source)->stats().drops, 0u);
}

}  // namespace
}  // namespace studio::capture

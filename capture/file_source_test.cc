// File replay: ordering, pixel exactness against OpenCV, frame numbering from the studio clock,
// looping, pacing (never early), stop(), corrupt files counted as drops, bad options.
// (Real data: file_source_dataset_test.cc.)
#include "capture/file_source.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "capture/take.h"

namespace studio::capture {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("file_source_test_" + std::to_string(getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string str() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
  static inline int counter_ = 0;
};

// A 32x24 image whose pixel (x, y) is (x*8, y*10, value) in RGB.
cv::Mat pattern_bgr(int value) {
  cv::Mat m(24, 32, CV_8UC3);
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(value, y * 10, x * 8);
  }
  return m;
}

Frame next_frame(FrameSource& source) {
  auto f = source.next(milliseconds(2000));
  EXPECT_TRUE(f) << (f ? "" : f.error().message);
  EXPECT_TRUE(f && *f);
  return f && *f ? std::move(**f) : Frame{};
}

TEST(FileSource, ReplaysAFolderInNameOrderWithExactPixels) {
  TempDir dir;
  // Written out of order, mixed formats; a text file and a sub-folder are ignored.
  ASSERT_TRUE(cv::imwrite(dir.file("b_001.png"), pattern_bgr(2)));
  ASSERT_TRUE(cv::imwrite(dir.file("a_000.PNG"), pattern_bgr(1)));
  ASSERT_TRUE(cv::imwrite(dir.file("c_002.bmp"), pattern_bgr(3)));
  cv::Mat grey(24, 32, CV_8UC1, cv::Scalar(77));
  ASSERT_TRUE(cv::imwrite(dir.file("d_003.png"), grey));
  std::ofstream(dir.file("notes.txt")) << "not an image";
  fs::create_directories(dir.file("sub.png"));

  FileSourceOptions o;
  o.path = dir.str();
  o.paced = false;
  o.start_ns = 1'000'000'000'000;  // frame 25000 of the default 25 fps clock at epoch 0
  auto source = FileSource::create(o);
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->size(), 4u);
  EXPECT_EQ((*source)->id(), fs::path(dir.str()).filename().string());
  ASSERT_TRUE((*source)->start());
  for (int i = 0; i < 4; ++i) {
    Frame f = next_frame(**source);
    EXPECT_EQ(f.capture_ns, o.start_ns + i * 40'000'000);
    EXPECT_EQ(f.frame, 25000u + i);
    EXPECT_FALSE(f.calibration);
    ASSERT_EQ(f.image.width(), 32);
    ASSERT_EQ(f.image.height(), 24);
    if (i < 3) {
      EXPECT_EQ(f.image(5, 7), (Rgb8{40, 70, uint8_t(i + 1)})) << i;
      EXPECT_EQ(f.image(31, 23), (Rgb8{248, 230, uint8_t(i + 1)})) << i;
    } else {
      EXPECT_EQ(f.image(5, 7), (Rgb8{77, 77, 77}));
    }
  }
  // End of the folder without loop: nullopt after the timeout, finished.
  auto end = (*source)->next(milliseconds(20));
  ASSERT_TRUE(end);
  EXPECT_FALSE(*end);
  EXPECT_TRUE((*source)->finished());
  EXPECT_EQ((*source)->stats().frames, 4u);
  EXPECT_EQ((*source)->stats().drops, 0u);
}

TEST(FileSource, LoopsAndNumbersFramesFromTheStudioClock) {
  TempDir dir;
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(cv::imwrite(dir.file(std::to_string(i) + ".png"), pattern_bgr(i)));
  FileSourceOptions o;
  o.id = "cam7";
  o.path = dir.str();
  o.loop = true;
  o.paced = false;
  o.fps = 50;
  o.clock = FrameClock{5'000'000, 20'000'000};  // 50 fps studio clock, epoch at 5 ms
  auto source = FileSource::create(o);
  ASSERT_TRUE(source);
  EXPECT_EQ((*source)->id(), "cam7");
  ASSERT_TRUE((*source)->start());
  Frame first = next_frame(**source);
  // start_ns = 0: the middle of the clock's next period, so no jitter can cross a boundary.
  EXPECT_EQ((first.capture_ns - o.clock.epoch_ns) % o.clock.period_ns, o.clock.period_ns / 2);
  for (int i = 1; i < 8; ++i) {
    Frame f = next_frame(**source);
    EXPECT_EQ(f.frame, first.frame + i);
    EXPECT_EQ(f.image(0, 0).b, uint8_t(i % 3)) << "frame " << i << " should show file " << i % 3;
  }
  EXPECT_FALSE((*source)->finished());
}

TEST(FileSource, PacedReplayIsNeverEarlyAndStopWakesIt) {
  TempDir dir;
  for (int i = 0; i < 2; ++i)
    ASSERT_TRUE(cv::imwrite(dir.file(std::to_string(i) + ".png"), pattern_bgr(i)));
  FileSourceOptions o;
  o.path = dir.str();
  o.loop = true;
  o.fps = 20;
  o.start_ns = 1;  // pacing relative to start()
  auto source = FileSource::create(o);
  ASSERT_TRUE(source);
  ASSERT_TRUE((*source)->start());
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i) next_frame(**source);
  // Frame 4 is due 4/20 s after start: a lower bound, independent of machine load.
  EXPECT_GE(std::chrono::steady_clock::now() - t0, milliseconds(195));
  // A short timeout before the next due time gives nullopt, not a frame.
  o.fps = 0.5;
  auto slow = FileSource::create(o);
  ASSERT_TRUE(slow);
  ASSERT_TRUE((*slow)->start());
  next_frame(**slow);
  auto none = (*slow)->next(milliseconds(10));
  ASSERT_TRUE(none);
  EXPECT_FALSE(*none);
  // stop() from another thread releases a next() waiting 10 s for a frame due in 2 s.
  std::thread stopper([&] {
    std::this_thread::sleep_for(milliseconds(50));
    (*slow)->stop();
  });
  const auto t1 = std::chrono::steady_clock::now();
  auto stopped = (*slow)->next(milliseconds(10000));
  stopper.join();
  ASSERT_TRUE(stopped);
  EXPECT_FALSE(*stopped);
  EXPECT_LT(std::chrono::steady_clock::now() - t1, milliseconds(1500));
}

TEST(FileSource, CorruptAndMismatchedFilesAreCountedDrops) {
  TempDir dir;
  ASSERT_TRUE(cv::imwrite(dir.file("0.png"), pattern_bgr(0)));
  std::ofstream(dir.file("1.png")) << "this is not a PNG";
  ASSERT_TRUE(cv::imwrite(dir.file("2.png"), cv::Mat(10, 10, CV_8UC3, cv::Scalar(1, 2, 3))));
  ASSERT_TRUE(cv::imwrite(dir.file("3.png"), pattern_bgr(3)));
  FileSourceOptions o;
  o.path = dir.str();
  o.paced = false;
  o.start_ns = 1'000'000'000;
  auto source = FileSource::create(o);
  ASSERT_TRUE(source);
  ASSERT_TRUE((*source)->start());
  Frame a = next_frame(**source);
  Frame b = next_frame(**source);
  EXPECT_EQ(a.image(0, 0).b, 0);
  EXPECT_EQ(b.image(0, 0).b, 3);
  EXPECT_EQ(b.frame, a.frame + 3);  // the two dropped files consumed their frame numbers
  EXPECT_EQ((*source)->stats().frames, 2u);
  EXPECT_EQ((*source)->stats().drops, 2u);

  TempDir broken;
  std::ofstream(broken.file("a.jpg")) << "garbage";
  std::ofstream(broken.file("b.png")) << "";
  o.path = broken.str();
  auto bad = FileSource::create(o);
  ASSERT_TRUE(bad);
  ASSERT_TRUE((*bad)->start());
  auto err = (*bad)->next(milliseconds(100));
  ASSERT_FALSE(err);
  EXPECT_NE(err.error().message.find("none of the 2 images"), std::string::npos);
}

// Writes one camera's take by the DESIGN §4 format (capture/take.h): frames 100.. with the given
// payloads; returns the byte offsets.
std::vector<IndexEntry> write_take(
    const std::string& dir, const std::vector<std::pair<PixelFormat, std::vector<uint8_t>>>& frames,
    uint32_t w, uint32_t h) {
  std::ofstream out(dir + "/" + kFramesFile, std::ios::binary);
  std::vector<IndexEntry> entries;
  uint64_t offset = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    FrameHeader header;
    header.frame = 100 + i;
    header.capture_ns = int64_t(4'000'000'000 + i * 40'000'000);
    header.width = w;
    header.height = h;
    header.format = frames[i].first;
    header.payload_size = frames[i].second.size();
    uint8_t bytes[kFrameHeaderSize];
    encode_frame_header(header, frames[i].second, bytes);
    out.write(reinterpret_cast<const char*>(bytes), kFrameHeaderSize);
    out.write(reinterpret_cast<const char*>(frames[i].second.data()), frames[i].second.size());
    entries.push_back({header.frame, offset});
    offset += kFrameHeaderSize + frames[i].second.size();
  }
  return entries;
}

TEST(FileSource, ReplaysARecordedTakeWithCrcChecks) {
  TempDir dir;
  const uint32_t w = 4, h = 3;
  std::vector<std::pair<PixelFormat, std::vector<uint8_t>>> frames;
  for (int i = 0; i < 3; ++i) {
    std::vector<uint8_t> rgb(w * h * 3);
    for (std::size_t k = 0; k < rgb.size(); ++k) rgb[k] = uint8_t(k * 7 + i);
    frames.emplace_back(PixelFormat::kRgb8, rgb);
  }
  frames.emplace_back(PixelFormat::kMono8, std::vector<uint8_t>(w * h, 99));
  const auto entries = write_take(dir.str(), frames, w, h);
  ASSERT_TRUE(write_index(dir.str(), entries));

  FileSourceOptions o;
  o.path = dir.str();
  o.paced = false;
  o.start_ns = 1'000'000'000'000;
  auto source = FileSource::create(o);
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_TRUE((*source)->is_take());
  EXPECT_EQ((*source)->size(), 4u);
  ASSERT_TRUE((*source)->start());
  for (int i = 0; i < 4; ++i) {
    Frame f = next_frame(**source);
    EXPECT_EQ(f.frame, 25000u + i);  // renumbered: replay is a new capture
    ASSERT_EQ(f.image.width(), int(w));
    ASSERT_EQ(f.image.height(), int(h));
    if (i < 3) {
      EXPECT_EQ(0, std::memcmp(f.image.data(), frames[i].second.data(), frames[i].second.size()));
    } else {
      EXPECT_EQ(f.image(3, 2), (Rgb8{99, 99, 99}));
    }
  }

  // A flipped payload byte fails the CRC: with the index, that frame is a counted drop.
  {
    std::fstream raw(dir.file(kFramesFile), std::ios::binary | std::ios::in | std::ios::out);
    raw.seekp(std::streamoff(entries[1].offset + kFrameHeaderSize + 5));
    raw.put(char(0xEE));
    raw.seekp(0, std::ios::end);
    raw.write("STFR\x01", 5);  // and a torn write at the end
  }
  auto corrupt = FileSource::create(o);
  ASSERT_TRUE(corrupt) << corrupt.error().message;
  ASSERT_TRUE((*corrupt)->start());
  Frame first = next_frame(**corrupt);
  Frame third = next_frame(**corrupt);
  EXPECT_EQ(third.frame, first.frame + 2);  // frame 1's slot was consumed by the drop
  EXPECT_EQ(0, std::memcmp(third.image.data(), frames[2].second.data(), frames[2].second.size()));
  next_frame(**corrupt);
  EXPECT_EQ((*corrupt)->stats().frames, 3u);
  EXPECT_EQ((*corrupt)->stats().drops, 1u);
  // Without the index the intact frames are found by scanning frames.raw (the corrupt frame and
  // the torn tail are skipped by the scan).
  fs::remove(dir.file(kIndexFile));
  auto rescanned = FileSource::create(o);
  ASSERT_TRUE(rescanned) << rescanned.error().message;
  EXPECT_EQ((*rescanned)->size(), 3u);
  ASSERT_TRUE((*rescanned)->start());
  for (int i : {0, 2, 3}) {
    Frame f = next_frame(**rescanned);
    if (i < 3) {
      EXPECT_EQ(0, std::memcmp(f.image.data(), frames[i].second.data(), frames[i].second.size()));
    } else {
      EXPECT_EQ(f.image(0, 0), (Rgb8{99, 99, 99}));
    }
  }

  // A take folder without any intact frame fails at create() with one line.
  TempDir empty;
  std::ofstream(empty.file(kFramesFile)) << "garbage, not a frame";
  o.path = empty.str();
  auto none = FileSource::create(o);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("no intact frames"), std::string::npos);
}

TEST(FileSource, BadOptionsAndFoldersFailWithOneLine) {
  FileSourceOptions o;
  EXPECT_FALSE(o.validate());
  o.path = "/nonexistent/folder";
  auto missing = FileSource::create(o);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("not a directory"), std::string::npos);
  TempDir empty;
  o.path = empty.str();
  auto none = FileSource::create(o);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("no PNG"), std::string::npos);
  o.fps = 0;
  EXPECT_FALSE(o.validate());
  o.fps = 25;
  o.clock.period_ns = 0;
  EXPECT_FALSE(o.validate());
  for (const auto& message : {missing.error().message, none.error().message}) {
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace studio::capture

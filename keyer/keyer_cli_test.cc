// Runs the real studio-keyer binary: the happy path and one clear error line for each bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "support/masks.h"
#include "test_frames.h"

namespace fs = std::filesystem;

namespace studio::keyer {
namespace {

struct Result {
  int status;
  std::string err;
};

Result run(const std::string& args) {
  const fs::path bin = fs::path(STUDIO_BINARY_DIR) / "keyer" / "studio-keyer";
  const fs::path err_file = fs::temp_directory_path() / ("keyer_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = bin.string() + " " + args + " >/dev/null 2>" + err_file.string();
  const int rc = std::system(cmd.c_str());
  std::ifstream in(err_file);
  std::string err((std::istreambuf_iterator<char>(in)), {});
  fs::remove(err_file);
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, err};
}

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

void write_rgb(const fs::path& p, const Image<Rgb8>& im) {
  cv::Mat m(im.height(), im.width(), CV_8UC3);
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x) {
      const Rgb8 c = im(x, y);
      m.at<cv::Vec3b>(y, x) = cv::Vec3b(c.b, c.g, c.r);
    }
  ASSERT_TRUE(cv::imwrite(p.string(), m));
}

class KeyerCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("keyer_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "in");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(KeyerCli, KeysAFolderIntoMasksWithTheSameNames) {
  const auto a = testing::make_frame(176, 144, 0.2), b = testing::make_frame(176, 144, 0.9);
  write_rgb(dir_ / "in" / "cam0.png", a.image);
  write_rgb(dir_ / "in" / "cam1.png", b.image);
  const Result r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat m = cv::imread((dir_ / "out" / "cam0.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(m.empty());
  Mask got(m.cols, m.rows);
  std::copy(m.datastart, m.dataend, got.data());
  EXPECT_GT(support::iou(got, a.truth), 0.95);  // a small frame: the boundary weighs much
  EXPECT_TRUE(fs::exists(dir_ / "out" / "cam1.png"));
}

TEST_F(KeyerCli, MissingFolderIsOneLine) {
  const Result r = run("key --input " + (dir_ / "nope").string() + " --output " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
}

TEST_F(KeyerCli, UnreadableImageIsOneLine) {
  std::ofstream(dir_ / "in" / "broken.png") << "this is not a PNG";
  const Result r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("broken.png"), std::string::npos) << r.err;
}

TEST_F(KeyerCli, PlateSizeMismatchIsOneLine) {
  write_rgb(dir_ / "in" / "cam0.png", testing::make_frame(176, 144, 0.2).image);
  write_rgb(dir_ / "plate.png", testing::make_frame(100, 80, 0.2).image);
  const Result r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string() +
                       " --key difference --plate " + (dir_ / "plate.png").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("100x80"), std::string::npos) << r.err;
}

TEST_F(KeyerCli, BadConfigAndUsageAreOneLine) {
  write_rgb(dir_ / "in" / "cam0.png", testing::make_frame(64, 48, 0.2).image);
  std::ofstream(dir_ / "keyer.yaml") << "keyer:\n  gain: 1.0\n  clip_whit: 50\n";
  Result r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string() +
                 " --config " + (dir_ / "keyer.yaml").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("keyer.yaml:3"), std::string::npos) << r.err;
  r = run("key --input " + (dir_ / "in").string() + " --output x --key red");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  r = run("key --input " + (dir_ / "in").string() + " --output x --key difference");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  std::ofstream(dir_ / "keyer.yaml") << "keyer:\n  cleanup:\n    keep_backing_gaps: maybe\n";
  r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string() +
          " --config " + (dir_ / "keyer.yaml").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("keep_backing_gaps"), std::string::npos) << r.err;
  // The documented example config loads.
  r = run("key --input " + (dir_ / "in").string() + " --output " + (dir_ / "out").string() +
          " --config " + STUDIO_SOURCE_DIR + "/keyer/keyer.example.yaml");
  EXPECT_EQ(r.status, 0) << r.err;
}

}  // namespace
}  // namespace studio::keyer

// Recorder: full takes are intact and indexed; a full queue drops and counts; a disk that fills
// (a file size limit, or a small tmpfs in a private mount namespace) stops the take cleanly with
// an error state, every earlier frame intact and no torn frame left.
#include "capture/recorder.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace studio::capture {
namespace {

std::string temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("recorder_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

Image<Rgb8> test_image(int w, int h, uint64_t frame) {
  Image<Rgb8> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img(x, y) = Rgb8{uint8_t(x + frame), uint8_t(y * 3), uint8_t(frame * 11 + x * y)};
  return img;
}

TakeInfo info_for(int w, int h) {
  TakeInfo t;
  t.take = "take1";
  t.camera_id = "cam0";
  t.width = uint32_t(w);
  t.height = uint32_t(h);
  t.period_ns = 40'000'000;
  t.start_frame = 1000;
  t.calibration_yaml = "  id: cam0\n";
  return t;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Recorder, WritesEveryFrameIntactWithIndexAndTakeYaml) {
  const std::string dir = temp_dir("full") + "/take1/cam0";
  auto rec = Recorder::start({.dir = dir, .queue_frames = 200}, info_for(64, 48));
  ASSERT_TRUE(rec) << rec.error().message;
  for (uint64_t f = 1000; f < 1040; ++f) {
    auto img = test_image(64, 48, f);
    ASSERT_TRUE((*rec)->push(f, int64_t(f) * 40'000'000, img.view()));
  }
  EXPECT_FALSE((*rec)->push(2000, 0, test_image(32, 48, 0).view()));  // wrong size
  (*rec)->add_drops(2);
  (*rec)->stop(1040);
  auto info = (*rec)->wait();
  ASSERT_TRUE(info) << info.error().message;
  EXPECT_EQ(info->frames, 40u);
  EXPECT_EQ(info->drops, 2u);
  EXPECT_EQ(*info->first_frame, 1000u);
  EXPECT_EQ(*info->last_frame, 1039u);
  EXPECT_EQ((*rec)->state(), RecorderState::kFinished);
  EXPECT_FALSE((*rec)->push(1041, 0, test_image(64, 48, 0).view()));

  auto scan = scan_frames(dir);
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(scan->intact.size(), 40u);
  EXPECT_EQ(scan->corrupt, 0u);
  EXPECT_TRUE(scan->tail.empty());
  auto index = read_index(dir);
  ASSERT_TRUE(index);
  EXPECT_EQ(*index, scan->intact);
  std::vector<uint8_t> pixels;
  auto h = read_frame(dir, (*index)[7], pixels);
  ASSERT_TRUE(h) << h.error().message;
  auto expect = test_image(64, 48, 1007);
  EXPECT_EQ(0, std::memcmp(pixels.data(), expect.data(), pixels.size()));
  EXPECT_EQ(h->capture_ns, 1007 * 40'000'000ll);

  const std::string yaml = slurp(dir + "/take.yaml");
  EXPECT_NE(yaml.find("status: complete"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("first_frame: 1000\nlast_frame: 1039\nframes: 40\ndrops: 2\n"),
            std::string::npos)
      << yaml;
  EXPECT_NE(yaml.find("stop_frame: 1040"), std::string::npos) << yaml;

  // A take is never overwritten.
  auto again = Recorder::start({.dir = dir}, info_for(64, 48));
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message.find("frames.raw"), std::string::npos);
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path().parent_path());
}

TEST(Recorder, FullQueueDropsAndCounts) {
  const std::string dir = temp_dir("drops") + "/t/cam0";
  auto rec = Recorder::start({.dir = dir, .queue_frames = 1}, info_for(320, 240));
  ASSERT_TRUE(rec) << rec.error().message;
  auto img = test_image(320, 240, 1);
  int accepted = 0;
  for (uint64_t f = 0; f < 300; ++f) accepted += (*rec)->push(f, 0, img.view()) ? 1 : 0;
  (*rec)->stop();
  auto info = (*rec)->wait();
  ASSERT_TRUE(info) << info.error().message;
  const auto stats = (*rec)->stats();
  EXPECT_EQ(info->frames, uint64_t(accepted));
  EXPECT_EQ(stats.queue_drops, uint64_t(300 - accepted));
  EXPECT_EQ(info->drops, stats.queue_drops);
  EXPECT_GT(stats.queue_drops, 0u);  // 300 pushes into a 1-slot queue cannot all fit
  EXPECT_EQ(scan_frames(dir)->intact.size(), std::size_t(accepted));
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path().parent_path());
}

// Runs a take into `dir` in a child process until the recorder reports an error (disk full),
// then scans the take in the child (a private tmpfs is only visible there) and reports
// "<setup> <written> <intact> <corrupt> <torn> <status-error> <message>" on a pipe.
// setup: 0 = ok, 1 = setup not permitted (skip).
enum class Limit { kFileSize, kTmpfs };

std::string disk_full_child(const std::string& dir, Limit limit, std::size_t frame_bytes) {
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    auto report = [&](const std::string& s) {
      (void)!::write(fds[1], s.data(), s.size());
      ::_exit(0);
    };
    if (limit == Limit::kFileSize) {
      ::signal(SIGXFSZ, SIG_IGN);
      rlimit rl{};
      rl.rlim_cur = rl.rlim_max = rlim_t(frame_bytes * 10 + frame_bytes / 2);
      if (::setrlimit(RLIMIT_FSIZE, &rl) != 0) report("1");
    } else {
      if (::unshare(CLONE_NEWNS) != 0) report("1");
      if (::mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) report("1");
      std::filesystem::create_directories(dir);
      if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=256k") != 0) report("1");
    }
    const std::string take_dir = dir + "/t/cam0";
    auto rec = Recorder::start({.dir = take_dir, .queue_frames = 4}, info_for(64, 48));
    if (!rec) report("2 start: " + rec.error().message);
    auto img = test_image(64, 48, 3);
    uint64_t f = 0;
    for (; f < 100000 && (*rec)->state() == RecorderState::kRecording; ++f) {
      (*rec)->push(f, 0, img.view());
      ::usleep(200);
    }
    auto result = (*rec)->wait();
    const auto stats = (*rec)->stats();
    auto scan = scan_frames(take_dir);
    if (!scan) report("2 scan: " + scan.error().message);
    const std::string yaml = [&] {
      std::ifstream in(take_dir + "/take.yaml");
      std::stringstream s;
      s << in.rdbuf();
      return s.str();
    }();
    std::ostringstream out;
    out << "0 " << stats.frames_written << " " << scan->intact.size() << " " << scan->corrupt << " "
        << (scan->file_bytes - scan->valid_bytes) << " "
        << ((*rec)->state() == RecorderState::kError && !result ? 1 : 0) << " "
        << (yaml.find("status: error") != std::string::npos ? 1 : 0) << " "
        << (result ? std::string("no-error") : result.error().message);
    report(out.str());
  }
  ::close(fds[1]);
  std::string text;
  char buf[512];
  ssize_t n;
  while ((n = ::read(fds[0], buf, sizeof buf)) > 0) text.append(buf, std::size_t(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return text;
}

void check_disk_full(const std::string& report, bool exact_ten, const char* what) {
  std::istringstream in(report);
  int setup = -1;
  in >> setup;
  if (setup == 1) GTEST_SKIP() << what << " not permitted here";
  ASSERT_EQ(setup, 0) << report;
  uint64_t written, intact, corrupt, torn;
  int error_state, yaml_error;
  in >> written >> intact >> corrupt >> torn >> error_state >> yaml_error;
  std::string message;
  std::getline(in, message);
  EXPECT_GT(written, 0u) << report;
  EXPECT_EQ(intact, written) << report;  // every frame written before the error is intact
  EXPECT_EQ(corrupt, 0u) << report;
  EXPECT_EQ(torn, 0u) << report;  // the torn frame was cut off
  EXPECT_EQ(error_state, 1) << report;
  EXPECT_EQ(yaml_error, 1) << report;
  if (exact_ten) {
    EXPECT_EQ(written, 10u) << report;
  }
  std::printf("%s: %llu frames intact, error:%s\n", what, (unsigned long long)written,
              message.c_str());
}

TEST(Recorder, FileSizeLimitStopsTakeCleanly) {
  const std::string dir = temp_dir("fsize");
  const std::size_t frame_bytes = kFrameHeaderSize + 64 * 48 * 3;
  const std::string report = disk_full_child(dir, Limit::kFileSize, frame_bytes);
  check_disk_full(report, true, "RLIMIT_FSIZE");
  EXPECT_NE(report.find("File too large"), std::string::npos) << report;
  std::filesystem::remove_all(dir);
}

TEST(Recorder, FullTmpfsStopsTakeCleanly) {
  const std::string dir = temp_dir("tmpfs") + "/mnt";
  const std::string report = disk_full_child(dir, Limit::kTmpfs, 0);
  check_disk_full(report, false, "tmpfs");
  if (!HasFatalFailure() && !IsSkipped()) {
    EXPECT_NE(report.find("No space left on device"), std::string::npos) << report;
  }
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path());
}

}  // namespace
}  // namespace studio::capture

// Durable takes: studio-capture records under a write layer that logs what each fdatasync made
// durable (capture/testing/sync_log_preload.cc, LD_PRELOAD); it is killed (-9) mid-take and
// every take file is cut back to its last synced size: what a power cut leaves when the page
// cache is lost. With sync_interval_ms 200 at 25 fps the loss is at most the frames of one
// interval (+ the one being written), and `studio-capture verify-take` rebuilds the index from
// the rest. The control, sync_interval_ms 60000, loses the whole take: the test can fail.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "capture/frame_clock.h"
#include "capture/take.h"
#include "core/clock.h"
#include "harness/fixture.h"
#include "wire/endpoint.h"

namespace studio::capture {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

class PowerLossTest : public testing::ProcessTest {
 protected:
  struct Loss {
    uint64_t written = 0, kept = 0;  // intact frames before and after the cut
    int verify_exit = -1;
    std::string verify_out;
  };

  Loss record_and_cut(int sync_interval_ms, const std::string& name) {
    Loss loss;
    const fs::path run = dir_ / name;
    fs::create_directories(run);
    std::ofstream(run / "capture.yaml")
        << "clock: {fps: 25}\ntakes_dir: takes\nstate_period: 0.2\nimage: {rate: 0}\n"
           "masks: false\nrecorder: {sync_interval_ms: "
        << sync_interval_ms
        << ", disk_mb_s: 1000}\ncameras:\n  - id: cam0\n"
           "    source: {type: sim, ring: 6, index: 0, width: 176, height: 144}\n";
    const fs::path log = run / "sync.log";
    testing::Env env = dds_.env();
    env.push_back({"LD_PRELOAD", STUDIO_SYNC_LOG_PRELOAD});
    env.push_back({"STUDIO_SYNC_LOG", log.string()});
    auto started =
        testing::Process::start({.name = "capture-" + name,
                                 .binary = testing::built_binary("capture/studio-capture"),
                                 .args = {"--config", (run / "capture.yaml").string()},
                                 .env = env,
                                 .dir = run});
    EXPECT_TRUE(started) << started.error().message;
    if (!started) return loss;
    processes_.push_back(std::move(*started));
    testing::Process& p = processes_.back();
    EXPECT_TRUE(p.wait_ready(30s)) << p.log();
    auto participant = wire::Participant::create().value();
    auto topic = wire::Topic<studio_CaptureCommand>::create(participant).value();
    auto commands = wire::Writer<studio_CaptureCommand>::create(participant, topic).value();
    EXPECT_TRUE(commands.wait_for_readers(1, 10s));
    FrameClock clock;
    const uint64_t start = clock.frame_at(realtime_ns()) + 10;
    wire::Owned<studio_CaptureCommand> c;
    wire::set(c->take, "t");
    c->action = studio_CAPTURE_START;
    c->at_frame = start;
    EXPECT_TRUE(commands.write(*c));
    // ~2.2 s of recording, then the power goes.
    while (clock.frame_at(realtime_ns()) < start + 55) std::this_thread::sleep_for(10ms);
    EXPECT_EQ(::kill(p.pid(), SIGKILL), 0);
    p.wait_exit(10s);

    const fs::path take = run / "takes" / "t" / "cam0";
    auto before = scan_frames(take.string());
    EXPECT_TRUE(before) << (before ? "" : before.error().message);
    if (!before) return loss;
    loss.written = before->intact.size();
    // The power cut: every file of the take back to its last durable size.
    std::map<std::string, uint64_t> durable;
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) {
      const auto space = line.find(' ');
      std::string path = line.substr(space + 1);
      // take.yaml and the index are written as NAME.tmp, synced, renamed and the folder
      // synced: durable under NAME.
      if (path.ends_with(".tmp")) path.resize(path.size() - 4);
      durable[path] = std::stoull(line.substr(0, space));
    }
    for (const auto& f : fs::directory_iterator(take)) {
      const std::string path = fs::canonical(f.path()).string();
      const uint64_t size = durable.count(path) ? durable[path] : 0;
      if (fs::file_size(f.path()) > size) fs::resize_file(f.path(), size);
    }
    auto after = scan_frames(take.string());
    EXPECT_TRUE(after);
    if (!after) return loss;
    loss.kept = after->intact.size();
    const std::string cmd = testing::built_binary("capture/studio-capture").string() +
                            " verify-take " + take.string() + " > " +
                            (run / "verify.json").string();
    loss.verify_exit = WEXITSTATUS(std::system(cmd.c_str()));
    std::ifstream v(run / "verify.json");
    loss.verify_out.assign(std::istreambuf_iterator<char>(v), {});
    return loss;
  }
};

TEST_F(PowerLossTest, LosesAtMostTheLastSyncIntervalAndVerifyTakeRebuildsTheRest) {
  const Loss synced = record_and_cut(200, "synced");
  std::printf("sync every 200 ms: %lu frames written, %lu survive the cut\n",
              (unsigned long)synced.written, (unsigned long)synced.kept);
  EXPECT_GE(synced.written, 45u);
  // 200 ms at 25 fps = 5 frames, plus the frame being written when the last sync ran.
  EXPECT_GE(synced.kept + 6, synced.written);
  EXPECT_GT(synced.kept, 0u);
  EXPECT_EQ(synced.verify_exit, 0) << synced.verify_out;
  EXPECT_NE(synced.verify_out.find("\"frames\": " + std::to_string(synced.kept)), std::string::npos)
      << synced.verify_out;
  EXPECT_NE(synced.verify_out.find("\"index_rebuilt\": true"), std::string::npos)
      << synced.verify_out;
  auto index = read_index((dir_ / "synced" / "takes" / "t" / "cam0").string());
  ASSERT_TRUE(index) << index.error().message;
  EXPECT_EQ(index->size(), synced.kept);

  // Control: syncing only at the end, the cut loses every frame.
  const Loss unsynced = record_and_cut(60000, "unsynced");
  std::printf("sync every 60 s: %lu frames written, %lu survive the cut\n",
              (unsigned long)unsynced.written, (unsigned long)unsynced.kept);
  EXPECT_GE(unsynced.written, 45u);
  EXPECT_EQ(unsynced.kept, 0u);
}

// The service warns at start when recording every camera would need more than the takes disk
// sustains: six 704x576 cameras at 25 fps need 182 MB/s.
TEST_F(PowerLossTest, WarnsWhenTheCamerasNeedMoreThanTheDiskSustains) {
  for (int disk : {50, 1000}) {
    std::ostringstream config;
    config << "clock: {fps: 25}\ntakes_dir: takes\nimage: {rate: 0}\nmasks: false\n"
           << "recorder: {disk_mb_s: " << disk << "}\ncameras:\n";
    for (int c = 0; c < 6; ++c)
      config << "  - id: cam" << c << "\n    source: {type: sim, ring: 6, index: " << c << "}\n";
    const fs::path path = dir_ / ("capture" + std::to_string(disk) + ".yaml");
    std::ofstream(path) << config.str();
    auto& p = spawn("capture" + std::to_string(disk), "capture/studio-capture",
                    {"--config", path.string()});
    ASSERT_TRUE(p.wait_ready(60s)) << p.log();
    EXPECT_EQ(p.stop(), 0);
    const std::string log = p.log();
    const bool warned = log.find("more than the " + std::to_string(disk) +
                                 " MB/s the takes disk sustains") != std::string::npos;
    EXPECT_EQ(warned, disk == 50) << log;
    EXPECT_NE(log.find("takes need 182.48"), std::string::npos) << log;
  }
}

}  // namespace
}  // namespace studio::capture

// Frame-accurate takes across six simulated cameras in one studio-capture process, each on its
// own capture thread with its own delivery jitter and sub-frame genlock offset, every frame's
// number stamped into its pixels (sim/frame_stamp.h). Three takes: in each, every camera's
// recording starts on exactly the commanded frame and holds every frame up to the stop frame,
// checked against the stamp in the recorded PIXELS as well as the header; in the third, camera 5
// loses one frame (drop_every) and the take reports exactly that drop where the pixels show the
// gap.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "capture/frame_clock.h"
#include "capture/take.h"
#include "core/clock.h"
#include "harness/fixture.h"
#include "sim/frame_stamp.h"
#include "wire/endpoint.h"

namespace studio::capture {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

constexpr int kCameras = 6, kW = 176, kH = 144, kLength = 20;
constexpr uint64_t kDropEvery = 37;  // camera 5 loses frames f with f % 37 == 36

class FrameAccurateTakeTest : public testing::ProcessTest {};

uint64_t yaml_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\n" + key + ": ");
  if (at == std::string::npos) return ~uint64_t(0);
  return std::stoull(text.substr(at + key.size() + 3));
}

TEST_F(FrameAccurateTakeTest, SixJitteredCamerasStartOnTheCommandedFrameCheckedInThePixels) {
  std::ostringstream config;
  config << "clock: {fps: 25}\ntakes_dir: takes\nstate_period: 0.2\nimage: {rate: 0}\n"
            "masks: false\nrecorder: {disk_mb_s: 1000}\ncameras:\n";
  for (int c = 0; c < kCameras; ++c)
    config << "  - id: cam" << c << "\n    source: {type: sim, ring: 6, index: " << c
           << ", width: " << kW << ", height: " << kH
           << ", stamp: true, offset_us: " << (c * 6000 - 15000)
           << ", jitter_us: " << (2000 + c * 3000) << (c == 5 ? ", drop_every: 37" : "") << "}\n";
  std::ofstream(dir_ / "capture.yaml") << config.str();
  auto participant = wire::Participant::create().value();
  auto state_topic = wire::Topic<studio_CameraState>::create(participant).value();
  auto states = wire::Reader<studio_CameraState>::create(participant, state_topic, 100).value();
  auto cmd_topic = wire::Topic<studio_CaptureCommand>::create(participant).value();
  auto commands = wire::Writer<studio_CaptureCommand>::create(participant, cmd_topic).value();
  auto& p =
      spawn("capture", "capture/studio-capture", {"--config", (dir_ / "capture.yaml").string()});
  ASSERT_TRUE(p.wait_ready(30s)) << p.log();
  ASSERT_TRUE(commands.wait_for_readers(1, 10s));

  std::map<std::string, std::string> take_of;  // latest CameraState take per camera
  auto all_show = [&](const std::string& take, bool recording_or_pending) {
    const auto deadline = std::chrono::steady_clock::now() + 15s;
    while (std::chrono::steady_clock::now() < deadline) {
      for (auto& s : states.take())
        if (s.meta.valid_data)
          take_of[std::string(wire::str(s.data->camera_id))] = std::string(wire::str(s.data->take));
      int n = 0;
      for (auto& [id, t] : take_of) n += (t == take) == recording_or_pending;
      if (n == kCameras) return true;
      std::this_thread::sleep_for(20ms);
    }
    return false;
  };
  auto command = [&](const std::string& take, bool start, uint64_t at) {
    wire::Owned<studio_CaptureCommand> c;
    wire::set(c->take, take);
    c->action = start ? studio_CAPTURE_START : studio_CAPTURE_STOP;
    c->at_frame = at;
    c->capture_ns = realtime_ns();
    ASSERT_TRUE(commands.write(*c));
  };
  FrameClock clock;  // 25 fps, epoch 0
  // A start frame >= `after` whose take [s, s + 20) holds no lost frame of camera 5 (clean), or
  // exactly one in its middle.
  auto start_frame = [](uint64_t after, bool with_drop) {
    for (uint64_t s = after;; ++s) {
      const uint64_t r = s % kDropEvery;
      if (!with_drop && r + kLength <= kDropEvery - 1) return s;
      if (with_drop && r >= 22 && r <= 30) return s;
    }
  };
  struct Take {
    std::string name;
    uint64_t start;
    bool with_drop;
  };
  std::vector<Take> takes;
  for (int t = 0; t < 3; ++t) {
    Take take{"take" + std::to_string(t), 0, t == 2};
    take.start = start_frame(clock.frame_at(realtime_ns()) + 20, take.with_drop);
    command(take.name, true, take.start);
    ASSERT_TRUE(all_show(take.name, true)) << p.log();
    command(take.name, false, take.start + kLength);
    // Recorded and finished: no camera names the take any more.
    ASSERT_TRUE(all_show(take.name, false)) << p.log();
    takes.push_back(take);
  }
  EXPECT_EQ(p.stop(), 0) << p.log();

  for (const Take& t : takes) {
    for (int c = 0; c < kCameras; ++c) {
      const std::string id = "cam" + std::to_string(c);
      const fs::path dir = dir_ / "takes" / t.name / id;
      std::ifstream y(dir / "take.yaml");
      const std::string yaml((std::istreambuf_iterator<char>(y)), {});
      ASSERT_NE(yaml.find("status: complete"), std::string::npos) << dir << "\n" << yaml;
      auto index = read_index(dir.string());
      ASSERT_TRUE(index) << index.error().message;
      // The frame camera 5 loses in the third take, if any.
      std::optional<uint64_t> lost;
      if (c == 5 && t.with_drop)
        for (uint64_t f = t.start; f < t.start + kLength; ++f)
          if (f % kDropEvery == kDropEvery - 1) lost = f;
      EXPECT_EQ(yaml_number(yaml, "drops"), lost ? 1u : 0u) << t.name << " " << id;
      ASSERT_EQ(index->size(), std::size_t(kLength) - (lost ? 1 : 0)) << t.name << " " << id;
      // Every recorded picture shows the frame its header names: the commanded first frame,
      // then each following one; the lost frame is missing from the pixels too.
      uint64_t expect = t.start;
      std::vector<uint8_t> pixels;
      for (const IndexEntry& e : *index) {
        if (lost && expect == *lost) ++expect;
        auto h = read_frame(dir.string(), e, pixels);
        ASSERT_TRUE(h) << h.error().message;
        const auto stamp = sim::read_frame_stamp(
            ImageView<const Rgb8>(reinterpret_cast<const Rgb8*>(pixels.data()), kW, kH));
        ASSERT_TRUE(stamp) << t.name << " " << id << ": no frame code in frame " << h->frame;
        EXPECT_EQ(*stamp, expect & ((uint64_t(1) << 40) - 1)) << t.name << " " << id;
        EXPECT_EQ(h->frame, expect) << t.name << " " << id;
        ++expect;
      }
      EXPECT_EQ(yaml_number(yaml, "first_frame"), t.start) << t.name << " " << id;
    }
  }
}

}  // namespace
}  // namespace studio::capture

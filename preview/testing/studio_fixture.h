#pragma once
// A simulated studio as real processes on loopback for the preview's tests: one studio-capture
// with the cameras of a ring + overhead (default 4 + 1) at 352x288 (the actor wears the frame code,
// sim/frame_code.h), studio-hull, optionally studio-scene with the default museum, and
// studio-preview instances. Like tests/harness/fixture.h's ProcessTest, with a watchdog long
// enough for a 40-second run on a loaded 2-core machine.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <numbers>

#include "harness/process.h"
#include "preview/viewpoint.h"
#include "sim/cameras.h"
#include "support/cameras.h"

namespace studio::preview::testing {

using namespace std::chrono_literals;
using studio::testing::Process;

class PreviewStudioTest : public ::testing::Test {
 protected:
  static constexpr int kWidth = 352, kHeight = 288;

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        studio::testing::make_test_dir(std::string(info->test_suite_name()) + "." + info->name());
    dds_ = studio::testing::DdsDomain::unique();
    dds_.apply_to_this_process();
  }
  void TearDown() override {
    for (auto& p : processes_) p.stop();
    // PREVIEW_KEEP_TEST_DIR=1 keeps the directory (recordings, logs) of a passing test too.
    if (HasFailure() || std::getenv("PREVIEW_KEEP_TEST_DIR")) {
      std::fprintf(stderr, "test dir: %s\n", dir_.c_str());
      for (auto& p : processes_)
        std::fprintf(stderr, "---- %s log ----\n%s\n", p.name().c_str(), p.log().c_str());
    } else {
      std::error_code ec;
      std::filesystem::remove_all(dir_, ec);
    }
  }

  Process& spawn(const std::string& name, const std::string& binary,
                 std::vector<std::string> args) {
    auto p = Process::start({.name = name,
                             .binary = studio::testing::built_binary(binary),
                             .args = std::move(args),
                             .env = dds_.env(),
                             .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  }

  // A program outside the build tree (tests/harness/xvfb-exec).
  Process& spawn_path(const std::string& name, const std::filesystem::path& binary,
                      std::vector<std::string> args) {
    auto p = Process::start(
        {.name = name, .binary = binary, .args = std::move(args), .env = dds_.env(), .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  }

  static sim::RingOptions ring(int count = 5) {
    sim::RingOptions r;
    r.count = count;
    r.width = kWidth;
    r.height = kHeight;
    r.focal_px *= double(kWidth) / 704.0;
    return r;
  }
  std::vector<Camera> cameras(int count = 5) const { return sim::ring_cameras(ring(count)); }

  // capture (5 cameras; the actor wears the frame code when `frame_code`) + hull, and the scene
  // server when `scene`; waits until each is ready.
  // `count` cameras: count - 1 on the ring and one overhead; `response`: per camera its colour
  // response (the capture config's sim `response`, sim::StudioOptions::camera_response), or
  // empty for identical cameras.
  // `source_extra`: more keys for every camera's sim source (e.g. ", gamma: 0.45").
  void start_studio(bool scene, bool frame_code = true, int count = 5,
                    const std::vector<std::array<double, 3>>& response = {},
                    const std::string& source_extra = "") {
    const auto rig = dir_ / "rig.yaml";
    ASSERT_TRUE(support::write_rig_yaml(cameras(count), rig));
    std::ofstream cap(dir_ / "capture.yaml");
    cap << "instance: cams\nclock: {fps: 25}\ntakes_dir: takes\nstate_period: 0.5\n"
           "image: {rate: 0}\ncameras:\n";
    for (int i = 0; i < count; ++i)
      cap << "  - id: cam" << i << "\n    source: {type: sim, ring: " << count << ", index: " << i
          << ", width: " << kWidth << ", height: " << kHeight
          << ", frame_code: " << (frame_code ? "true" : "false")
          << (response.empty() ? std::string()
                               : ", response: [" + std::to_string(response[i][0]) + ", " +
                                     std::to_string(response[i][1]) + ", " +
                                     std::to_string(response[i][2]) + "]")
          << source_extra << "}\n";
    cap.close();
    std::ofstream(dir_ / "hull.yaml")
        << "instance: hull\nhull:\n  rig: rig.yaml\n  box: [-1.5, 0.0, -1.5, 1.5, 2.4, 1.5]\n"
           "  grid: 96\n  deadline_ms: 40\n  min_cameras: 4\n  threads: 1\n  mesh: true\n"
           "  refine: true\n";
    Process& c =
        spawn("capture", "capture/studio-capture", {"--config", (dir_ / "capture.yaml").string()});
    Process& h = spawn("hull", "hull/studio-hull", {"--config", (dir_ / "hull.yaml").string()});
    ASSERT_TRUE(c.wait_ready(60s)) << c.log();
    ASSERT_TRUE(h.wait_ready(60s)) << h.log();
    if (scene) {
      std::ofstream(dir_ / "scene.yaml")
          << "instance: scene0\nclock: {fps: 25, epoch_ns: 0, source: studio}\nscene: "
          << STUDIO_SCENE_DEFAULT_DIR << "/scene.yaml\n";
      Process& s =
          spawn("scene", "scene/studio-scene", {"--config", (dir_ / "scene.yaml").string()});
      ASSERT_TRUE(s.wait_ready(60s)) << s.log();
    }
  }

  // Writes preview.yaml; returns its path.
  // `extra`: more preview.yaml lines.
  std::string preview_config(const std::string& instance, int wait_ms = 400,
                             const std::string& extra = "") {
    const auto path = dir_ / (instance + ".yaml");
    std::ofstream(path) << "instance: " << instance << "\nwait_ms: " << wait_ms << "\n" << extra;
    return path.string();
  }

  // The options every headless preview of the actor alone takes: `config` (a preview.yaml),
  // `view`, no overlays, the studio's image size.
  std::vector<std::string> actor_preview_args(const std::string& config, const Viewpoint& view) {
    return {"--headless",  "--config",      config,
            "--viewpoint", to_string(view), "--overlays",
            "none",        "--size",        std::to_string(kWidth) + "x" + std::to_string(kHeight)};
  }

  // A headless preview from `view` drawing the actor only (--overlays none) at the studio's
  // image size: 30 meshes recorded to <dir>/<name> (frames.jsonl and PNGs), the last as
  // <dir>/<name>.png, the summary as JSON on its log. `config`: more preview.yaml lines;
  // `args`: more command-line options.
  Process& recorded_preview(const std::string& name, const Viewpoint& view,
                            const std::string& config = "",
                            const std::vector<std::string>& args = {}) {
    std::vector<std::string> a = actor_preview_args(preview_config(name, 1000, config), view);
    for (const std::string& x :
         {std::string("--frames"), std::string("30"), std::string("--timeout"), std::string("120"),
          std::string("--record"), (dir_ / name).string(), std::string("--screenshot"),
          (dir_ / (name + ".png")).string(), std::string("--json")})
      a.push_back(x);
    a.insert(a.end(), args.begin(), args.end());
    return spawn(name, "preview/studio-preview", std::move(a));
  }

  // A headless preview from `view` pooling every textured mesh into its colour balance
  // (colour_balance_every: 1) for `seconds`: the actor alone at the studio's image size, every
  // drawn mesh recorded to <dir>/rec, the summary as JSON on its log; `more`: more options.
  Process& balancing_preview(const Viewpoint& view, int seconds,
                             const std::vector<std::string>& more = {}) {
    std::vector<std::string> a =
        actor_preview_args(preview_config("director", 1000, "colour_balance_every: 1\n"), view);
    for (const std::string& x :
         {std::string("--duration"), std::to_string(seconds), std::string("--record"),
          (dir_ / "rec").string(), std::string("--screenshot"), (dir_ / "last.png").string(),
          std::string("--json")})
      a.push_back(x);
    a.insert(a.end(), more.begin(), more.end());
    return spawn("preview", "preview/studio-preview", std::move(a));
  }

  studio::testing::Watchdog watchdog_{std::chrono::seconds(280)};
  std::filesystem::path dir_;
  studio::testing::DdsDomain dds_;
  std::deque<Process> processes_;
};

}  // namespace studio::preview::testing

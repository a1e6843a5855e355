// The projector service with `output: window` (issue 15 item 3: "a GLFW full-screen window on a
// named monitor, same code"), as a real process on a private Xvfb display (tests/harness/xvfb-exec;
// Xvfb's screen 960x540, the test projector's size). The test reads the X display itself (XGetImage
// of the root window: what the monitor shows, independent of the projector's GL code) and compares
// it with the frame the projector published for the same, static input: the thumbnail (read back
// from the renderer's target, as headless) and the full-resolution blackout mask. A monitor name
// that is not connected fails at start with one line listing the connected monitors; the name
// listed there is then the positive control.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>

#include "core/clock.h"
#include "harness/fixture.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "testing/projectors.h"
#include "testing/x_screen.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/sample.h"
#include "wire/scene_convert.h"
#include "yaml_io/rig_yaml.h"

namespace studio::projector {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class WindowOutputTest : public studio::testing::ProcessTest {
 protected:
  // The projector on a private Xvfb display; "DISPLAY=:N" is written to x.env.
  studio::testing::Process& spawn_in_xvfb(const std::string& monitor) {
    Rig rig;
    rig.projectors.push_back(testing::half_back_projector());
    EXPECT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()).has_value());
    const auto config = dir_ / ("projector-" + std::to_string(processes_.size()) + ".yaml");
    std::ofstream(config) << "instance: proj-window\nstatus_period: 0.2\nprojector:\n"
                          << "  rig: rig.yaml\n  id: proj0\n  rate: 10\n"
                          << "  default_eye: [0, 1.6, 1.5]\n  output: window\n  monitor: "
                          << monitor << "\n";
    auto args = studio::testing::xvfb_exec("960x540x24", dir_ / "x.env");
    const std::string launcher = args.front();
    args.erase(args.begin());
    for (const std::string& a :
         {studio::testing::built_binary("projector/studio-projector").string(),
          std::string("--config"), config.string()})
      args.push_back(a);
    auto p = studio::testing::Process::start({.name = "projector-" + monitor,
                                              .binary = launcher,
                                              .args = args,
                                              .env = dds_.env(),
                                              .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  }
};

TEST_F(WindowOutputTest, FullScreenWindowOnTheNamedMonitorShowsTheFrame) {
  // An unknown monitor: one line at start naming the connected ones.
  auto& bad = spawn_in_xvfb("no-such-monitor");
  const auto code = bad.wait_exit(60s);
  ASSERT_TRUE(code.has_value()) << bad.log();
  EXPECT_NE(*code, 0);
  std::smatch m;
  const std::string log = bad.log();
  ASSERT_TRUE(std::regex_search(
      log, m, std::regex(R"(monitor 'no-such-monitor' not found \(connected: ([^,)]+))")))
      << log;
  const std::string monitor = m[1];
  std::printf("Xvfb's monitor: %s\n", monitor.c_str());

  // The named monitor: the projector runs full screen there.
  auto& node = spawn_in_xvfb(monitor);
  ASSERT_TRUE(node.wait_ready(60s)) << node.log();
  std::string display = slurp(dir_ / "x.env");  // "DISPLAY=:N\n"
  ASSERT_EQ(display.rfind("DISPLAY=", 0), 0u) << display;
  display = display.substr(8, display.find('\n') - 8);
  const std::string xauthority;  // xvfb-exec's server has no access control

  auto p = wire::Participant::create().value();
  auto frame_topic = wire::Topic<studio_ProjectorFrame>::create(p).value();
  auto frames = wire::Reader<studio_ProjectorFrame>::create(p, frame_topic, 16).value();
  auto node_topic = wire::Topic<studio_SceneNode>::create(p).value();
  auto nodes = wire::Writer<studio_SceneNode>::create(p, node_topic).value();
  auto mesh_topic = wire::Topic<studio_ActorMesh>::create(p).value();
  auto meshes = wire::Writer<studio_ActorMesh>::create(p, mesh_topic).value();

  // A static input: the demo scene and one still actor box (the eye stays the default one).
  auto description =
      scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml").value();
  scene_assets::AssetCache cache;
  auto scene = scene_assets::build_scene(description, cache, 0).value();
  ASSERT_TRUE(nodes.wait_for_readers(1, 20s));
  for (const auto& [id, n] : scene.nodes()) {
    wire::Owned<studio_SceneNode> s;
    ASSERT_TRUE(wire::from_core(n, *s).has_value());
    ASSERT_TRUE(nodes.write(*s).has_value());
  }
  ASSERT_TRUE(meshes.wait_for_readers(1, 20s));
  wire::Owned<studio_ActorMesh> mesh;
  {
    std::vector<float> v;
    for (int i = 0; i < 8; ++i)
      v.insert(v.end(), {0.2f + (i & 1 ? 0.25f : -0.25f), 1.0f + (i & 2 ? 0.25f : -0.25f),
                         -0.5f + (i & 4 ? 0.25f : -0.25f)});
    const std::vector<uint32_t> t = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                     2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    wire::set(mesh->actor_id, "actor0");
    mesh->frame = 7;
    mesh->capture_ns = realtime_ns();
    mesh->source_frame = 7;
    wire::assign(mesh->vertices, v);
    wire::assign(mesh->triangles, t);
  }
  ASSERT_TRUE(meshes.write(*mesh).has_value());

  // Frames with the mask and every scene node drawn; then the screen and the newest frame.
  auto newest_with_mask = [&]() {
    std::optional<wire::Owned<studio_ProjectorFrame>> got;
    for (auto& s : frames.take(16))
      if (s.meta.valid_data && s.data->actors == 1) got = std::move(s.data);
    return got;
  };
  std::optional<wire::Owned<studio_ProjectorFrame>> first;
  for (auto until = SteadyClock::now() + 30s; !first && SteadyClock::now() < until;) {
    first = newest_with_mask();
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(first) << node.log();
  std::this_thread::sleep_for(1s);  // the scene's assets loaded; the input is static from here
  (void)newest_with_mask();
  std::optional<wire::Owned<studio_ProjectorFrame>> frame;
  for (auto until = SteadyClock::now() + 10s; !frame && SteadyClock::now() < until;) {
    frame = newest_with_mask();
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(frame);
  std::this_thread::sleep_for(300ms);  // a few more (identical) frames shown
  testing::XScreen x;
  for (int attempt = 0; attempt < 300 && x.width == 0; ++attempt) {  // a loaded machine: retry
    if (attempt > 0) std::this_thread::sleep_for(100ms);
    x = testing::read_x_screen(display, xauthority);
  }
  ASSERT_GT(x.width, 0)
      << "XOpenDisplay(" << display << ") failed, XAUTHORITY " << xauthority
      << ", socket /tmp/.X11-unix/X" << display.substr(1)
      << " exists: " << std::filesystem::exists("/tmp/.X11-unix/X" + display.substr(1))
      << ", auth file exists: " << std::filesystem::exists(xauthority)
      << ", projector running: " << node.running()
      << ", lock: " << slurp("/tmp/.X" + display.substr(1) + "-lock") << ", xdpyinfo: "
      << std::system(
             ("XAUTHORITY=" + xauthority + " xdpyinfo -display " + display + " | head -3").c_str());
  const cv::Mat screen(x.height, x.width, CV_8UC3, x.rgb.data());
  ASSERT_EQ(screen.cols, 960);
  ASSERT_EQ(screen.rows, 540);

  // The window shows the frame: the screen, scaled as the renderer makes its thumbnail, matches
  // the published thumbnail; the blackout mask's pixels are black on the screen.
  const studio_ProjectorFrame& f = **frame;
  ASSERT_EQ(f.thumb_width * f.thumb_height * 3, wire::view(f.thumbnail).size());
  const cv::Mat thumb(int(f.thumb_height), int(f.thumb_width), CV_8UC3,
                      const_cast<uint8_t*>(wire::view(f.thumbnail).data()));
  cv::Mat small;
  cv::resize(screen, small, thumb.size(), 0, 0, cv::INTER_AREA);
  cv::Mat diff;
  cv::absdiff(small, thumb, diff);
  const double mean_diff = cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2];
  cv::Scalar mean, stddev;
  cv::meanStdDev(small, mean, stddev);
  const Mask blackout = wire::to_core(f).value().to_mask();
  int black_in_mask = 0, in_mask = 0;
  for (int y = 0; y < 540; ++y)
    for (int x = 0; x < 960; ++x)
      if (blackout(x, y)) {
        ++in_mask;
        const cv::Vec3b c = screen.at<cv::Vec3b>(y, x);
        black_in_mask += c[0] == 0 && c[1] == 0 && c[2] == 0;
      }
  std::printf(
      "window %s: thumbnail mean |diff| %.2f (sum over RGB), screen stddev %.1f, "
      "blackout %d px, %d of them black on the screen\n",
      display.c_str(), mean_diff, stddev[0], in_mask, black_in_mask);
  EXPECT_GT(stddev[0], 10.0) << "the screen shows a picture, not a flat colour";
  EXPECT_LT(mean_diff, 3.0);
  EXPECT_GT(in_mask, 2000);
  EXPECT_EQ(black_in_mask, in_mask);
  node.stop();
  EXPECT_NE(node.log().find("full-screen window on monitor " + monitor), std::string::npos)
      << node.log();
}

}  // namespace
}  // namespace studio::projector

// studio-preview's window under Xvfb (GLFW + Dear ImGui on Mesa), driven by its test hook
// (--test-script, gui.h) against the running simulated studio: two instances with different
// viewpoints side by side; one opens the Cameras panel and moves cam0's Gain slider, the other
// opens the Projectors panel. Checked:
// the screenshot (the panel's title bar and the slider with its value at the places the window
// reports, the scene drawn in the 3D view, the two views differ) and the wire (the simulated
// camera's read-back on studio/camera/state becomes the new value). And the View panel's "Match
// cameras" button (node/camera_matching.h), pressed by the hook: its result drawn, the cameras
// set.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "sim/studio.h"
#include "testing/studio_fixture.h"
#include "wire/endpoint.h"

namespace studio::preview::testing {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// [x, y, w, h(, value)] of `key` in the layout file.
std::vector<double> rect(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key +
                      "\":\\[([-0-9.e]+),([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)(,([-0-9.e]+))?\\]");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return {};
  std::vector<double> out;
  for (int i : {1, 2, 3, 4, 6})
    if (m[i].matched) out.push_back(std::stod(m[i]));
  return out;
}

// Pixels in the rectangle that are near white (ImGui's text in the dark style).
int text_pixels(const cv::Mat& img, const std::vector<double>& r) {
  int n = 0;
  for (int y = int(r[1]); y < int(r[1] + r[3]) && y < img.rows; ++y)
    for (int x = int(r[0]); x < int(r[0] + r[2]) && x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      n += c[0] > 200 && c[1] > 200 && c[2] > 200;
    }
  return n;
}

TEST_F(PreviewStudioTest, GuiPanelsDriveTheStudioAndTwoViewsRunSideBySide) {
  start_studio(true, false, 5);
  auto p = wire::Participant::create().value();
  auto topic = wire::Topic<studio_CameraState>::create(p).value();
  auto states = wire::Reader<studio_CameraState>::create(p, topic).value();
  const std::string director = (dir_ / "director.txt").string(), op = (dir_ / "op.txt").string();
  std::ofstream(director) << "wait_meshes 3\nopen cameras\nwait 2\nset cam0 Gain 7.5\nwait 2\n"
                             "screenshot "
                          << (dir_ / "director.png").string() << "\nquit\n";
  std::ofstream(op) << "wait_meshes 3\nopen projectors\nwait 1\nscreenshot "
                    << (dir_ / "operator.png").string() << "\nquit\n";
  std::map<std::string, Process*> guis;
  const std::map<std::string, std::string> views{
      {"director", "eye=0.6,1.9,3.7,at=0,1.1,0,fov=55"},
      {"operator", "eye=-3.5,2.5,1.0,at=0,1.0,0,fov=60"}};
  // Each on its own Xvfb display (xvfb-exec: `xvfb-run -a` races when two start at once).
  for (const auto& [name, view] : views) {
    auto args = studio::testing::xvfb_exec("1024x768x24", dir_ / (name + ".xenv"));
    const std::string launcher = args.front();
    args.erase(args.begin());
    for (const std::string& a :
         {studio::testing::built_binary("preview/studio-preview").string(), std::string("--config"),
          preview_config(name), std::string("--viewpoint"), view, std::string("--size"),
          std::string("960x640"), std::string("--test-script"), name == "director" ? director : op})
      args.push_back(a);
    guis[name] = &spawn_path(name, launcher, args);
  }
  for (auto& [name, g] : guis) {
    const auto code = g->wait_exit(std::chrono::seconds(150));
    ASSERT_TRUE(code.has_value()) << name << " did not finish";
    ASSERT_EQ(*code, 0) << g->log();
  }
  // The wire: the simulated camera reads back the new gain.
  double gain = -1;
  for (auto deadline = std::chrono::steady_clock::now() + 15s;
       gain != 7.5 && std::chrono::steady_clock::now() < deadline;) {
    for (auto& s : states.take())
      if (s.meta.valid_data && wire::str(s.data->camera_id) == "cam0")
        for (const auto& f : wire::view(s.data->features))
          if (wire::str(f.name) == "Gain") gain = f.value;
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_DOUBLE_EQ(gain, 7.5) << "cam0's read-back";
  // The screenshot: the panel and the slider where the window says, with text in them.
  const cv::Mat shot = cv::imread((dir_ / "director.png").string(), cv::IMREAD_COLOR);
  const cv::Mat other = cv::imread((dir_ / "operator.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(shot.empty());
  ASSERT_FALSE(other.empty());
  const std::string layout = slurp(dir_ / "director.png.json");
  const auto window = rect(layout, "Cameras");
  const auto slider = rect(layout, "cam0/Gain");
  ASSERT_EQ(window.size(), 4u) << layout;
  ASSERT_EQ(slider.size(), 5u) << layout;
  EXPECT_DOUBLE_EQ(slider[4], 7.5);
  const std::vector<double> title{window[0], window[1], window[2], 19};
  EXPECT_GT(text_pixels(shot, title), 10) << "the title 'Cameras' in the title bar";
  EXPECT_GT(text_pixels(shot, slider), 10) << "the value drawn in the slider";
  // The 3D view: the museum fills most of the window (few pixels of the clear colour) and the
  // two instances see it from different places.
  int background = 0, differ = 0;
  for (int y = 0; y < shot.rows; ++y)
    for (int x = 0; x < shot.cols; ++x) {
      const cv::Vec3b c = shot.at<cv::Vec3b>(y, x);
      background +=
          std::abs(c[0] - 18) <= 2 && std::abs(c[1] - 13) <= 2 && std::abs(c[2] - 13) <= 2;
      const cv::Vec3b d = other.at<cv::Vec3b>(y, x);
      differ += std::abs(c[0] - d[0]) + std::abs(c[1] - d[1]) + std::abs(c[2] - d[2]) > 30;
    }
  EXPECT_LT(background, shot.rows * shot.cols / 2) << "the scene is drawn in the 3D view";
  EXPECT_GT(differ, shot.rows * shot.cols / 4) << "two viewpoints, two pictures";
  const std::string op_layout = slurp(dir_ / "operator.png.json");
  EXPECT_TRUE(rect(op_layout, "Cameras").empty()) << "the operator did not open the panel";
  // The operator's Projectors panel (no projector runs here: the panel says so), its title
  // drawn where the window reports it.
  const auto projectors = rect(op_layout, "Projectors");
  ASSERT_EQ(projectors.size(), 4u) << op_layout;
  EXPECT_GT(text_pixels(other, {projectors[0], projectors[1], projectors[2], 19}), 10)
      << "the title 'Projectors' in the title bar";
  EXPECT_TRUE(rect(layout, "Projectors").empty()) << "the director did not open it";
  EXPECT_NE(op_layout.find("\"meshes\":"), std::string::npos);
}

// The View panel's "Match cameras" pressed through the test hook on a rig whose cameras differ
// (cam1 two thirds of a stop up): the panel shows what it sent, under the button where the
// window reports it, and the simulated cameras read back the new Gain / white balance.
TEST_F(PreviewStudioTest, GuiMatchCamerasButtonSetsTheCameras) {
  auto response = sim::random_camera_response(9, 3, 0.1, 0.05);
  for (double& g : response[1]) g *= 1.6;
  start_studio(false, false, 9, response);
  auto p = wire::Participant::create().value();
  auto topic = wire::Topic<studio_CameraState>::create(p).value();
  auto states = wire::Reader<studio_CameraState>::create(p, topic).value();
  const std::string script = (dir_ / "match.txt").string();
  // Pressed once the whole rig is sampled (16 rig samples, one per 0.5 s).
  std::ofstream(script) << "wait_meshes 3\nopen view\nwait 10\npress match_cameras\nwait 2\n"
                           "screenshot "
                        << (dir_ / "match.png").string() << "\nquit\n";
  auto args = studio::testing::xvfb_exec("1024x768x24", dir_ / "match.xenv");
  const std::string launcher = args.front();
  args.erase(args.begin());
  for (const std::string& a :
       {studio::testing::built_binary("preview/studio-preview").string(), std::string("--config"),
        preview_config("director", 400, "colour_balance_every: 1\n"), std::string("--viewpoint"),
        std::string("eye=0.3,1.6,2.6,at=0,1.0,0,fov=50"), std::string("--size"),
        std::string("960x640"), std::string("--test-script"), script})
    args.push_back(a);
  Process& g = spawn_path("director", launcher, args);
  const auto code = g.wait_exit(std::chrono::seconds(150));
  ASSERT_TRUE(code.has_value()) << "did not finish";
  ASSERT_EQ(*code, 0) << g.log();
  const std::string layout = slurp(dir_ / "match.png.json");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(layout, m, std::regex(R"re("match":"([^"]*)")re"))) << layout;
  const std::string said = m[1];
  std::printf("the panel says: %s\n", said.c_str());
  EXPECT_NE(said.find("controls sent to"), std::string::npos) << said;
  EXPECT_NE(said.find("(9 matched"), std::string::npos) << "the whole rig: " << said;
  // After the match the rig is sampled afresh: the panel says what the button sends now.
  ASSERT_TRUE(std::regex_search(layout, m, std::regex(R"re("match_source":"([^"]*)")re")))
      << layout;
  EXPECT_NE(std::string(m[1]).find("until the whole rig is sampled"), std::string::npos) << m[1];
  // The button and the result beside it, drawn where the layout says.
  const cv::Mat shot = cv::imread((dir_ / "match.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(shot.empty());
  const auto button = rect(layout, "View/Match cameras");
  ASSERT_EQ(button.size(), 5u) << layout;
  EXPECT_GT(text_pixels(shot, button), 10) << "the button's label";
  EXPECT_GT(text_pixels(shot, {button[0] + button[2], button[1], 300, button[3]}), 10)
      << "the result beside the button";
  // The wire: some camera no longer at its defaults (Gain 0 dB, white balance 1).
  int changed = 0;
  for (auto deadline = std::chrono::steady_clock::now() + 10s;
       changed == 0 && std::chrono::steady_clock::now() < deadline;) {
    for (auto& s : states.take())
      if (s.meta.valid_data)
        for (const auto& f : wire::view(s.data->features)) {
          const std::string name(wire::str(f.name));
          changed += (name == "Gain" && f.value != 0) ||
                     ((name == "BalanceRatioRed" || name == "BalanceRatioBlue") && f.value != 1);
        }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_GT(changed, 0) << "no camera reads back a matched control";
}

}  // namespace
}  // namespace studio::preview::testing

// studio-calibrate projector end to end on the simulated studio (issue 15 item 4): the projector
// shows the ChArUco pattern the CLI draws (--draw-pattern), the simulator renders it as the
// studio's six calibrated cameras see it with their LED rings off and a 4x exposure (noise on),
// once on the cloth and twice on a white board held in the beam; the CLI detects, triangulates,
// fits the screen and the projector and writes it into rig.yaml. The written projector must be
// the simulated one within 5 mm (centre), 0.1 degrees (orientation) and 0.5 % (focal length).
// Refusals beside that positive control: captures of the cloth alone (one plane, taken with the
// LED rings on at the normal exposure) do not determine the projector: one line, exit 1; usage
// errors exit 2; --help says how to get a usable view.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sim/cameras.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio {
namespace {

// The CLI's default pattern, rendered with 6 x 6 rays per camera pixel so that the pattern's edges
// (projector pixel squares) are area-integrated.
const std::string kPattern = "charuco:16x9:110:80:DICT_4X4_100";
constexpr int kSamples = 6;

struct CliRun {
  int code = -1;
  std::string out, err;
};

CliRun run_cli(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd =
      std::string(STUDIO_CALIBRATE_EXE) + " " + args + " >" + out.string() + " 2>" + err.string();
  CliRun r;
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// A white board facing the projector (turned 12 degrees about the vertical), centred on its
// optical axis at `distance`, large enough to hold the whole beam.
sim::Board board_in_beam(const Camera& projector, double distance, double turn) {
  const Eigen::Vector3d C = projector.centre_in_world(), axis = projector.axis_in_world();
  sim::Board b;
  b.centre = C + distance * axis;
  const Eigen::Vector3d facing =
      Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitY()) * Eigen::Vector3d(-axis);
  b.x_axis = facing.cross(Eigen::Vector3d::UnitY()).normalized();
  b.y_axis = b.x_axis.cross(facing).normalized();
  const double w = projector.width / projector.intrinsics.fx * distance;
  b.half_width = 0.6 * w;
  b.half_height = 0.6 * w * projector.height / projector.width + 0.1;
  return b;
}

class ProjectorCalibrationCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("projector_sim_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    cameras_ = sim::ring_cameras();
    truth_ =
        sim::studio_projector(sim::Cyclorama{}, {0.5, 2.5, 3.8}, 6.0, 1920, 1080, {0.0, 1.2, -4.5});
    Rig rig;
    rig.cameras = cameras_;
    ASSERT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()));
    const CliRun drawn = run_cli(
        "projector --pattern " + kPattern + " --draw-pattern " + (dir_ / "pattern.png").string(),
        dir_);
    ASSERT_EQ(drawn.code, 0) << drawn.err;
    const cv::Mat grey = cv::imread((dir_ / "pattern.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(grey.cols, 1920);
    frame_ = Image<Rgb8>(1920, 1080);
    for (int y = 0; y < 1080; ++y)
      for (int x = 0; x < 1920; ++x) {
        const uint8_t g = grey.at<uint8_t>(y, x);
        frame_(x, y) = {g, g, g};
      }
  }
  void TearDown() override {
    if (!std::getenv("STUDIO_KEEP_TEST_DIR")) fs::remove_all(dir_);
  }

  // Renders one capture: every camera's image with the pattern projected (frame 0).
  void capture(const std::string& name, std::vector<sim::Board> boards, double ring,
               double exposure) {
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::idle;
    so.actor.seed = 5;
    so.projector_light.projectors.push_back({truth_, frame_});
    so.projector_light.boards = std::move(boards);
    so.projector_light.ring_level = ring;
    so.projector_light.exposure = exposure;
    so.projector_light.samples = kSamples;
    auto studio = sim::SimulatedStudio::create(cameras_, so);
    ASSERT_TRUE(studio) << studio.error().message;
    std::vector<Image<Rgb8>> images;
    studio->render_all(0, &images, nullptr);
    fs::create_directories(dir_ / "captures" / name);
    for (std::size_t c = 0; c < images.size(); ++c) {
      cv::Mat rgb(images[c].height(), images[c].width(), CV_8UC3, images[c].data());
      cv::Mat bgr;
      cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
      ASSERT_TRUE(
          cv::imwrite((dir_ / "captures" / name / (cameras_[c].id + ".png")).string(), bgr));
    }
  }

  fs::path dir_;
  std::vector<Camera> cameras_;
  Projector truth_;
  Image<Rgb8> frame_;
};

TEST_F(ProjectorCalibrationCli, RecoversTheSimulatedProjector) {
  capture("cloth", {}, 0.0, 4.0);
  capture("board_near", {board_in_beam(truth_.camera, 4.0, 0.25)}, 0.0, 4.0);
  capture("board_mid", {board_in_beam(truth_.camera, 4.8, 0.0)}, 0.0, 4.0);
  capture("board_far", {board_in_beam(truth_.camera, 5.6, -0.25)}, 0.0, 4.0);
  const fs::path out = dir_ / "out.yaml";
  const CliRun r = run_cli("projector --rig " + (dir_ / "rig.yaml").string() + " --captures " +
                               (dir_ / "captures").string() +
                               " --boards board_near,board_mid,board_far --pattern " + kPattern +
                               " --out " + out.string() + " --json",
                           dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  std::printf("%s%s", r.err.c_str(), r.out.c_str());
  auto rig = yaml::read_rig(out.string());
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), cameras_.size());
  const Projector* p = rig->find_projector("proj0");
  ASSERT_NE(p, nullptr);
  const Camera& got = p->camera;
  const Camera& want = truth_.camera;
  const double centre_mm = 1000 * (got.centre_in_world() - want.centre_in_world()).norm();
  const Eigen::Matrix3d dR = got.cam_from_world.R() * want.cam_from_world.R().transpose();
  const double angle_deg = Eigen::AngleAxisd(dR).angle() * 180 / M_PI;
  const double focal = std::max(std::abs(got.intrinsics.fx / want.intrinsics.fx - 1),
                                std::abs(got.intrinsics.fy / want.intrinsics.fy - 1));
  std::printf("centre error %.2f mm, rotation %.4f deg, focal %.3f %%\n", centre_mm, angle_deg,
              100 * focal);
  EXPECT_LE(centre_mm, 5.0);
  EXPECT_LE(angle_deg, 0.1);
  EXPECT_LE(focal, 0.005);
  // The screen lies on the back wall (z = -4.5).
  for (const Eigen::Vector3d& c : p->screen) EXPECT_NEAR(c.z(), -4.5, 0.02);
}

TEST_F(ProjectorCalibrationCli, ClothAloneIsRefusedInOneLine) {
  capture("cloth", {}, 1.0, 1.0);
  const CliRun r = run_cli("projector --rig " + (dir_ / "rig.yaml").string() + " --captures " +
                               (dir_ / "captures").string() + " --quiet",
                           dir_);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // Usage errors and --help.
  EXPECT_EQ(run_cli("projector --rig", dir_).code, 2);
  EXPECT_EQ(run_cli("projector --pattern chessboard:9x6:0.1 --draw-pattern x.png", dir_).code, 1);
  const CliRun help = run_cli("projector --help", dir_);
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("LED ring"), std::string::npos);
  EXPECT_NE(help.out.find("exposure"), std::string::npos);
}

}  // namespace
}  // namespace studio

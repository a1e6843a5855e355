// studio-projector render as a process: the default museum scene from an eye through the back-wall
// projector's screen, with an actor mesh masked; the blackout mask lands where the projector's own
// camera model puts the grown mesh; both forms agree; bad input is one line and a non-zero exit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "projector/mask_geometry.h"
#include "testing/projectors.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;
using namespace studio;

namespace {

struct Outcome {
  int status;
  std::string out, err;
};

fs::path temp_dir() {
  const fs::path d =
      fs::temp_directory_path() / ("projector_cli_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

Outcome run(const std::string& args) {
  const fs::path d = temp_dir();
  const std::string cmd = std::string(STUDIO_PROJECTOR_CLI) + " " + args + " >" +
                          (d / "stdout").string() + " 2>" + (d / "stderr").string();
  const int rc = std::system(cmd.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(d / "stdout"), slurp(d / "stderr")};
}

void expect_one_line_error(const Outcome& r, const std::string& words) {
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
}

const std::string kScene = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml";

// A 0.5 m box as an ASCII PLY (studio frame) and the same mesh for the expected mask.
projector::ActorMesh write_box(const fs::path& path) {
  projector::ActorMesh m;
  const Eigen::Vector3f c(0.2f, 1.0f, -0.5f);
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back(c +
                         0.25f * Eigen::Vector3f(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  std::ofstream f(path);
  f << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
       "property float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : m.vertices) f << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : m.triangles) f << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return m;
}

cv::Mat expected_mask(const Camera& cam, const projector::ActorMesh& m) {
  cv::Mat out(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  for (const auto& t : m.triangles) {
    std::vector<cv::Point> pts;
    for (uint32_t k : t) {
      Eigen::Vector2d px;
      EXPECT_TRUE(cam.project(m.vertices[k].cast<double>(), &px));
      pts.emplace_back(int(std::lround(px.x() * 16)), int(std::lround(px.y() * 16)));
    }
    cv::fillConvexPoly(out, pts, cv::Scalar(255), cv::LINE_8, 4);
  }
  return out;
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  const double i = cv::countNonZero(a & b), u = cv::countNonZero(a | b);
  return u > 0 ? i / u : 0;
}

class ProjectorCli : public ::testing::Test {
 protected:
  void SetUp() override {
    projector_ = projector::testing::studio_projectors()[0];
    projector_.camera.id = "proj0";
    Rig rig;
    rig.projectors.push_back(projector_);
    rig_ = (temp_dir() / "rig.yaml").string();
    ASSERT_TRUE(yaml::write_rig(rig, rig_).has_value());
    mesh_ = write_box(temp_dir() / "actor.ply");
  }
  std::string base() const {
    return "render --rig " + rig_ + " --projector proj0 --scene " + kScene + " --head 0.1,1.65,1.2";
  }
  Projector projector_;
  std::string rig_;
  projector::ActorMesh mesh_;
};

}  // namespace

TEST_F(ProjectorCli, HelpDocumentsRenderAndTheServiceKeys) {
  const Outcome r = run("--help");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("studio-projector render --rig"), std::string::npos);
  EXPECT_NE(r.out.find("two_pass"), std::string::npos);
  EXPECT_NE(r.out.find("margin:"), std::string::npos);  // the config keys of the service
}

TEST_F(ProjectorCli, RendersTheSceneAndMasksTheActorInBothForms) {
  const fs::path d = temp_dir();
  const std::string mesh = (d / "actor.ply").string();
  cv::Mat frames[2];
  const char* forms[] = {"single_pass", "two_pass"};
  for (int k = 0; k < 2; ++k) {
    const fs::path png = d / (std::string(forms[k]) + ".png"),
                   mask = d / (std::string(forms[k]) + "_mask.png");
    const Outcome r = run(base() + " --mesh " + mesh + " --margin 0.02 --form " + forms[k] +
                          " --out " + png.string() + " --mask-out " + mask.string() + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\"blackout_px\""), std::string::npos) << r.out;
    frames[k] = cv::imread(png.string());
    ASSERT_EQ(frames[k].cols, 1920);
    ASSERT_EQ(frames[k].rows, 1080);
    cv::Scalar mean, stddev;
    cv::meanStdDev(frames[k], mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30);  // a picture, not a cleared frame
    const cv::Mat got = cv::imread(mask.string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat want =
        expected_mask(projector_.camera, projector::grow_mesh(mesh_, 0.02).value());
    EXPECT_GT(iou(got, want), 0.97) << forms[k];
    // The blacked-out pixels are black in the frame.
    cv::Mat grey;
    cv::cvtColor(frames[k], grey, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(grey & got), 0);
  }
  // Same geometry, two forms: the pictures agree away from edges (PSNR over the frame).
  EXPECT_GT(cv::PSNR(frames[0], frames[1]), 25.0);
}

TEST_F(ProjectorCli, BadInputIsOneLine) {
  const fs::path png = temp_dir() / "bad.png";
  expect_one_line_error(run(base() + " --out " + png.string() + " --form three_pass"), "--form");
  expect_one_line_error(run("render --rig " + rig_ + " --projector nope --scene " + kScene +
                            " --head 0,1.6,1 --out " + png.string()),
                        "no projector 'nope'");
  // An eye behind the screen (the back wall is at z = -2).
  expect_one_line_error(run("render --rig " + rig_ + " --projector proj0 --scene " + kScene +
                            " --head 0,1.6,-3 --out " + png.string()),
                        "--head");
  expect_one_line_error(run(base() + " --mesh /nonexistent.ply --out " + png.string()), "--mesh");
  // A degenerate screen: collinear corners (write_rig refuses to write one: the text is edited).
  std::ifstream in(rig_);
  std::stringstream text;
  text << in.rdbuf();
  std::string edited = text.str();
  const auto at = edited.find("corners:");
  ASSERT_NE(at, std::string::npos);
  edited = edited.substr(0, at) + "corners: [[-2, 0, -2], [0, 0, -2], [2, 0, -2], [4, 0, -2]]}\n";
  const std::string bad_rig = (temp_dir() / "bad_rig.yaml").string();
  std::ofstream(bad_rig) << edited;
  const Outcome r = run("render --rig " + bad_rig + " --projector proj0 --scene " + kScene +
                        " --head 0,1.6,1 --out " + png.string());
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// studio-scene as a process: render the default scene headless, and refuse bad input with one
// line on stderr and a non-zero exit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int status;
  std::string out, err;
};

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("scene_cli_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

Outcome run(const std::string& args) {
  const fs::path d = temp_dir();
  const std::string cmd = std::string(STUDIO_SCENE_CLI) + " " + args + " >" + (d / "stdout").string() +
                          " 2>" + (d / "stderr").string();
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

}  // namespace

TEST(SceneCli, RendersTheDefaultScene) {
  const fs::path png = temp_dir() / "default.png";
  const Outcome r = run("render --size 320x180 --out " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat image = cv::imread(png.string());
  ASSERT_EQ(image.cols, 320);
  ASSERT_EQ(image.rows, 180);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 30);  // a picture, not a cleared frame
}

TEST(SceneCli, ViewFrameAndMeshChangeThePicture) {
  const fs::path d = temp_dir();
  ASSERT_EQ(run("render --size 320x180 --out " + (d / "a.png").string()).status, 0);
  // An actor: an ASCII PLY tetrahedron-ish box in front of the camera.
  std::ofstream(d / "actor.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                    "property float y\nproperty float z\nelement face 4\n"
                                    "property list uchar int vertex_indices\nend_header\n"
                                    "-0.5 0 0\n0.5 0 0\n0 1.8 0\n0 0.9 0.5\n3 0 1 2\n3 0 1 3\n3 1 2 3\n3 0 2 3\n";
  const Outcome with_mesh = run("render --size 320x180 --mesh " + (d / "actor.ply").string() + " --out " + (d / "b.png").string());
  ASSERT_EQ(with_mesh.status, 0) << with_mesh.err;
  const Outcome moved = run("render --size 320x180 --view eye=0,1.7,0,at=0,1.5,-8,fov=50 --frame 40 --out " +
                        (d / "c.png").string());
  ASSERT_EQ(moved.status, 0) << moved.err;
  const cv::Mat a = cv::imread((d / "a.png").string()), b = cv::imread((d / "b.png").string()),
                c = cv::imread((d / "c.png").string());
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 1000.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 1000.0);
}

TEST(SceneCli, HelpListsRender) {
  const Outcome r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("studio-scene render"), std::string::npos);
  EXPECT_EQ(run("render --help").status, 0);
}

TEST(SceneCli, BadInputIsOneLineAndNonZero) {
  const fs::path d = temp_dir();
  const std::string out = " --out " + (d / "x.png").string();
  expect_one_line_error(run("render --scene " + (d / "none.yaml").string() + out), "none.yaml");
  std::ofstream(d / "malformed.yaml") << "set: [museum.glb\nnodes: {\n";
  expect_one_line_error(run("render --scene " + (d / "malformed.yaml").string() + out), "malformed.yaml");
  std::ofstream(d / "unknown.yaml") << "set_idd: x\n";
  expect_one_line_error(run("render --scene " + (d / "unknown.yaml").string() + out), "set_idd");
  std::ofstream(d / "noset.yaml") << "set: nowhere.glb\n";
  expect_one_line_error(run("render --scene " + (d / "noset.yaml").string() + out), "nowhere.glb");
  expect_one_line_error(run("render --view eye=1,2" + out), "--view");
  expect_one_line_error(run("render --view eye=0,0,0,at=0,0,0" + out), "--view");
  expect_one_line_error(run("render --view eye=1,2,3,at=0,0,0,fov=abc" + out), "--view");
  expect_one_line_error(run("render --size 0x10" + out), "--size");
  expect_one_line_error(run("render"), "--out");
  expect_one_line_error(run("render --mesh " + (d / "none.ply").string() + out), "--mesh");
  expect_one_line_error(run("serve"), "unknown command");
  expect_one_line_error(run("--config scene.yaml"), "--config");
  expect_one_line_error(run(""), "command");
  EXPECT_FALSE(fs::exists(d / "x.png"));
}

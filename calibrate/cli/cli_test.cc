// studio-calibrate end to end: a synthetic rig through observations.yaml, the opencv-doc stereo
// images through --images, and the failure cases (one line on stderr, non-zero exit).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "calibrate/synthetic.h"
#include "calibrate/text.h"
#include "observations_yaml.h"
#include "yaml_io/rig_yaml.h"

namespace studio::calibrate {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(STUDIO_BINARY_DIR) / "calibrate_cli_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Outcome run(const fs::path& dir, const std::string& args) {
  const std::string cmd = format("{} {} >{} 2>{}", STUDIO_CALIBRATE_EXE, args,
                                 (dir / "stdout").string(), (dir / "stderr").string());
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir / "stdout"), slurp(dir / "stderr")};
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(CalibrateCli, SyntheticObservationsToRigReportPlotsAndOpenCv) {
  const fs::path dir = scratch("synthetic");
  const SyntheticStudio s = make_synthetic_studio(SyntheticStudioOptions{});
  std::ofstream(dir / "observations.yaml") << format_observations_yaml(s.observations, SyntheticStudioOptions{}.target);
  const Outcome r = run(dir, format("cameras --observations {} --out {} --report {}",
                                (dir / "observations.yaml").string(), (dir / "rig.yaml").string(),
                                (dir / "report.json").string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("iteration"), std::string::npos);  // progress on the terminal
  auto rig = yaml::read_rig((dir / "rig.yaml").string());
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 8u);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_LT((rig->cameras[i].centre_in_world() - s.cameras[i].centre_in_world()).norm(), 0.005);
    EXPECT_EQ(rig->cameras[i].distortion.model, Distortion::Model::radial);
    EXPECT_TRUE(fs::exists(dir / "report_residuals" / ("residuals_" + s.cameras[i].id + ".png")));
    EXPECT_TRUE(fs::exists(dir / "rig_opencv" / (s.cameras[i].id + ".yaml")));
  }
  const std::string json = slurp(dir / "report.json");
  for (const char* key : {"\"rms_px\"", "\"heldout\"", "\"iterations\"", "\"seconds\"", "\"outliers\"",
                          "\"frames\"", "\"cameras\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
}

TEST(CalibrateCli, HelpAndUsage) {
  const fs::path dir = scratch("usage");
  EXPECT_EQ(run(dir, "--help").code, 0);
  const Outcome r = run(dir, "cameras --observations x.yaml --out r.yaml --bogus");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
}

TEST(CalibrateCli, MalformedObservationsFileIsOneLineWithItsLine) {
  const fs::path dir = scratch("malformed");
  std::ofstream(dir / "obs.yaml") << "target: {rows: 10, cols: 10, spacing: 0.1}\nframes:\n"
                                     "  - id: 0\n    views:\n      cam0: [[0, 1.0], [1, 2, 3]]\n";
  Outcome r = run(dir, format("cameras --observations {} --out {}", (dir / "obs.yaml").string(),
                          (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("obs.yaml:5"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "rig.yaml"));
  std::ofstream(dir / "bad.yaml") << "frames: [\n";
  r = run(dir, format("cameras --observations {} --out {}", (dir / "bad.yaml").string(),
                      (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  r = run(dir, format("cameras --observations {} --out {}", (dir / "missing.yaml").string(),
                      (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
}

// Garbage that makes yaml-cpp throw, and a small file whose aliases repeat one list millions of
// times: one line and exit 1 each (found while writing observations_yaml_fuzz).
TEST(CalibrateCli, GarbageAndAliasBombsAreOneLine) {
  const fs::path dir = scratch("garbage");
  std::string bytes;
  for (int i = 0; i < 1024; ++i) bytes += static_cast<char>(i * 37 % 256);
  std::ofstream(dir / "binary.yaml", std::ios::binary) << bytes;
  std::ofstream(dir / "deep.yaml") << "frames: " << std::string(5000, '[') << std::string(5000, ']');
  std::string bomb = "frames:\n  - &f {id: 0, views: {";
  std::string points = "[";
  for (int i = 0; i < 300; ++i) points += i ? ", [0, 1, 2]" : "[0, 1, 2]";
  for (int c = 0; c < 100; ++c) bomb += format("{}c{}: {}", c ? ", " : "", c, c ? "*p" : "&p " + points + "]");
  bomb += "}}\n";
  for (int f = 0; f < 200; ++f) bomb += "  - *f\n";  // 201 x 100 x 300 = 6.03M points in 5.6 kB
  std::ofstream(dir / "bomb.yaml") << bomb;
  for (const char* name : {"binary.yaml", "deep.yaml", "bomb.yaml"}) {
    const Outcome r = run(dir, format("cameras --observations {} --out {}", (dir / name).string(),
                                      (dir / "rig.yaml").string()));
    EXPECT_EQ(r.code, 1) << name;
    EXPECT_EQ(lines(r.err), 1) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    if (std::string(name) == "bomb.yaml") {
      EXPECT_NE(r.err.find("more than 5000000 observations"), std::string::npos) << r.err;
    }
  }
}

// Found by observations_yaml_fuzz: a frame without views was written as a bare "views:" that
// did not read back.
TEST(ObservationsYaml, FrameWithoutViewsRoundTrips) {
  Observations obs;
  obs.cameras.push_back({"cam0", 0, 0});
  obs.frames.push_back({"0", Placement::origin, false, {View{"cam0", {{3, {1.5, 2.25}}}}}});
  obs.frames.push_back({"1", Placement::free, true, {}});
  auto back = parse_observations_yaml(format_observations_yaml(obs, *parse_target_spec("grid:10x10:0.1")),
                                      "roundtrip.yaml");
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->observations.frames.size(), 2u);
  EXPECT_TRUE(back->observations.frames[1].views.empty());
  EXPECT_TRUE(back->observations.frames[1].holdout);
  EXPECT_EQ(back->observations.frames[0].views[0].points[0].pixel, Eigen::Vector2d(1.5, 2.25));
}

TEST(CalibrateCli, CameraWithNoSharedFrameIsNamed) {
  const fs::path dir = scratch("island");
  SyntheticStudio s = make_synthetic_studio(SyntheticStudioOptions{});
  std::vector<FrameObservations> own;
  for (auto& f : s.observations.frames)
    std::erase_if(f.views, [&](const View& v) {
      if (v.camera_id != "cam3") return false;
      own.push_back({f.id + "b", Placement::free, false, {v}});
      return true;
    });
  s.observations.frames.insert(s.observations.frames.end(), own.begin(), own.end());
  std::ofstream(dir / "obs.yaml") << format_observations_yaml(s.observations, SyntheticStudioOptions{}.target);
  const Outcome r = run(dir, format("cameras --observations {} --out {} --quiet", (dir / "obs.yaml").string(),
                                (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("camera cam3 shares no frame"), std::string::npos) << r.err;
}

TEST(CalibrateCli, UnreadableImageAndBoardNeverDetected) {
  const fs::path dir = scratch("images");
  fs::create_directories(dir / "broken" / "cam0");
  std::ofstream(dir / "broken" / "cam0" / "0.png") << "not a png";
  Outcome r = run(dir, format("cameras --images {} --target chessboard:9x6:0.025 --out {}",
                          (dir / "broken").string(), (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("cannot read image"), std::string::npos) << r.err;

  fs::create_directories(dir / "blank" / "cam0");
  fs::create_directories(dir / "blank" / "cam1");
  const cv::Mat grey(480, 640, CV_8U, cv::Scalar(128));
  for (const char* cam : {"cam0", "cam1"})
    for (int f = 0; f < 2; ++f) cv::imwrite((dir / "blank" / cam / format("{}.png", f)).string(), grey);
  r = run(dir, format("cameras --images {} --target chessboard:9x6:0.025 --out {} --quiet",
                      (dir / "blank").string(), (dir / "rig.yaml").string()));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("detected in none of the 4 images"), std::string::npos) << r.err;
}

TEST(CalibrateCli, OpenCvDocStereoImages) {
  const fs::path data = "/usr/share/doc/opencv-doc/examples/data";
  if (!fs::exists(data / "left01.jpg")) GTEST_SKIP() << "opencv-doc is not installed";
  const fs::path dir = scratch("stereo");
  for (const char* side : {"left", "right"}) {
    fs::create_directories(dir / "images" / side);
    for (int i = 1; i <= 14; ++i)
      if (fs::exists(data / format("{}{:02d}.jpg", side, i)))
        fs::create_symlink(data / format("{}{:02d}.jpg", side, i),
                           dir / "images" / side / format("{:02d}.jpg", i));
  }
  const Outcome r = run(dir, format("cameras --images {} --target chessboard:9x6:0.025 --out {} "
                                "--report {} --holdout 03 --save-observations {}",
                                (dir / "images").string(), (dir / "rig.yaml").string(),
                                (dir / "report.json").string(), (dir / "obs.yaml").string()));
  ASSERT_EQ(r.code, 0) << r.err;
  auto rig = yaml::read_rig((dir / "rig.yaml").string());
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_EQ(rig->cameras.size(), 2u);
  EXPECT_EQ(rig->cameras[0].width, 640);
  EXPECT_NEAR(rig->cameras[1].centre_in_world().norm(), 0.0834, 0.002);  // OpenCV: 0.08349 m
  // The saved detections read back.
  auto saved = read_observations_yaml((dir / "obs.yaml").string());
  ASSERT_TRUE(saved) << saved.error().message;
  EXPECT_GE(saved->observations.frames.size(), 13u);
}

}  // namespace
}  // namespace studio::calibrate

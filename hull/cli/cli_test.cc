// studio-hull offline, run as a process: a mesh from a synthetic studio's masks, and one clear
// error line each for a missing camera mask, a mask of the wrong size and an empty box.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/rig.h"
#include "support/cameras.h"
#include "testing/mesh_read.h"
#include "testing/synthetic.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull {
namespace {

struct Result {
  int code;
  std::string out, err;
};

Result run(const std::string& args, const fs::path& dir) {
  const std::string cmd = std::string(STUDIO_HULL_CLI) + " " + args + " >" +
                          (dir / "out.txt").string() + " 2>" + (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  const auto slurp = [](const fs::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  return {WEXITSTATUS(status), slurp(dir / "out.txt"), slurp(dir / "err.txt")};
}

class HullCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hull_cli_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "masks");
    const testing::Scene scene = testing::actor();
    const auto cameras = support::camera_ring(4, 352, 288, 4.0, 1.6, {0, 1, 0}, 300);
    ASSERT_TRUE(support::write_rig_yaml(cameras, dir_ / "rig.yaml"));
    for (const Camera& c : cameras) {
      const Mask m = testing::render_mask(c, scene).to_mask();
      cv::Mat img(m.height(), m.width(), CV_8U, const_cast<uint8_t*>(m.data()));
      for (const char* frame : {"", "7/", "8/"}) {
        fs::create_directories(dir_ / "masks" / frame);
        ASSERT_TRUE(cv::imwrite((dir_ / "masks" / frame / (c.id + ".png")).string(), img));
      }
    }
    base_ = "offline --rig " + (dir_ / "rig.yaml").string() + " --grid 64 ";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::string base_;
};

TEST_F(HullCli, SingleFrameAndSequenceWithTiming) {
  Result r = run(base_ + "--masks " + (dir_ / "masks").string() + " --box -1,0,-1,1,2,1 --out " +
                     (dir_ / "a.glb").string() + " --timing",
                 dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GT(fs::file_size(dir_ / "a.glb"), 1000u);
  EXPECT_NE(r.out.find("\"cut\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"mesh\":"), std::string::npos);
  // The sequence: masks/7 and masks/8 exist beside the single-frame pngs; a folder of only frames.
  for (const auto& e : fs::directory_iterator(dir_ / "masks"))
    if (e.is_regular_file()) fs::remove(e.path());
  r = run(base_ + "--masks " + (dir_ / "masks").string() +
              " --box -1,0,-1,1,2,1 --frames 8:9 --out " + (dir_ / "seq").string(),
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "seq" / "8.ply"));
  EXPECT_FALSE(fs::exists(dir_ / "seq" / "7.ply"));
}

TEST_F(HullCli, RejectsMissingMask) {
  for (const auto& e : fs::directory_iterator(dir_ / "masks"))
    if (e.is_regular_file()) fs::remove(e.path());
  fs::remove(dir_ / "masks" / "8" / "cam2.png");
  const Result r = run(base_ + "--masks " + (dir_ / "masks").string() +
                           " --box -1,0,-1,1,2,1 --frames 8:8 --out " + (dir_ / "seq").string(),
                       dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("missing mask for camera cam2"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(HullCli, RejectsMaskOfWrongSize) {
  cv::Mat small(100, 120, CV_8U, cv::Scalar(0));
  ASSERT_TRUE(cv::imwrite((dir_ / "masks" / "cam1.png").string(), small));
  const Result r = run(base_ + "--masks " + (dir_ / "masks").string() +
                           " --box -1,0,-1,1,2,1 --out " + (dir_ / "a.ply").string(),
                       dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("mask is 120x100, camera cam1 is 352x288"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(HullCli, RejectsEmptyBox) {
  const Result r = run(base_ + "--masks " + (dir_ / "masks").string() +
                           " --box -1,0,-1,1,0,1 --out " + (dir_ / "a.ply").string(),
                       dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("box: empty along y"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// The visibility policy through the process (issue 18): a box much looser than the 4-camera rig.
// --min-views 0 (the former --outside keep) keeps what no camera sees; the default (2) cuts it
// but, with only 4 cameras 90 degrees apart, keeps where exactly two opposite cameras' cones
// cross beyond the other two's images; --min-views 3 gives the tight box's hull. --timing
// reports the box coverage.
TEST_F(HullCli, DefaultPolicyIgnoresWhatTheCamerasDoNotSee) {
  const auto hull_volume = [&](const std::string& box, const std::string& extra, Result* r) {
    *r = run(base_ + "--masks " + (dir_ / "masks").string() + " --box " + box + " --out " +
                 (dir_ / "v.ply").string() + " --timing " + extra,
             dir_);
    EXPECT_EQ(r->code, 0) << r->err;
    auto mesh = testing::read_ply((dir_ / "v.ply").string());
    EXPECT_TRUE(mesh) << (mesh ? "" : mesh.error().message);
    return mesh ? mesh->volume() : 0.0;
  };
  const auto number = [](const std::string& json, const std::string& key) {
    const auto at = json.find("\"" + key + "\": ");
    EXPECT_NE(at, std::string::npos) << key << " in " << json;
    return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 4));
  };
  Result tight, loose, keep;
  const double v_tight = hull_volume("-1,0,-1,1,2,1", "", &tight);
  const double v_loose = hull_volume("-4,-1,-4,4,5,4", "--grid 256", &loose);
  const double v_keep = hull_volume("-4,-1,-4,4,5,4", "--grid 256 --min-views 0", &keep);
  Result three;
  const double v_three = hull_volume("-4,-1,-4,4,5,4", "--grid 256 --min-views 3", &three);
  std::printf("tight %.4f, loose: default %.4f, min-views 0 %.4f, min-views 3 %.4f m^3\n", v_tight,
              v_loose, v_keep, v_three);
  EXPECT_GT(v_tight, 0.01);
  // 64 columns over 2 m and 256 over 8 m: the same cells.
  EXPECT_GT(v_keep, 20 * v_tight);
  EXPECT_LT(v_loose, 0.2 * v_keep);
  EXPECT_GT(v_loose, 0.97 * v_tight);
  EXPECT_NEAR(v_three / v_tight, 1.0, 0.05);
  EXPECT_EQ(number(tight.out, "min_views"), 2);
  EXPECT_NEAR(number(tight.out, "unseen_fraction"), 0.0, 1e-9);
  EXPECT_GT(number(loose.out, "unseen_fraction"), 0.2);
  EXPECT_GE(number(loose.out, "below_min_views_fraction"), number(loose.out, "unseen_fraction"));
  EXPECT_EQ(number(keep.out, "below_min_views_fraction"), 0);
  // --progress: the coverage line on stderr.
  Result r;
  hull_volume("-4,-1,-4,4,5,4", "--progress", &r);
  EXPECT_NE(r.err.find("box coverage:"), std::string::npos) << r.err;
}

TEST_F(HullCli, HelpAndBadArguments) {
  const Result help = run("offline --help", dir_);
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--min-views N     visibility policy (default 2)"), std::string::npos);
  for (const char* bad : {"--min-views x", "--min-views 65", "--outside keep"}) {
    const Result b = run(base_ + "--masks " + (dir_ / "masks").string() +
                             " --box -1,0,-1,1,2,1 --out " + (dir_ / "a.ply").string() + " " + bad,
                         dir_);
    EXPECT_EQ(b.code, 2) << bad;
    EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
    EXPECT_NE(b.err.find(std::string(bad).substr(0, std::string(bad).find(' '))), std::string::npos)
        << b.err;
  }
  EXPECT_EQ(run("--help", dir_).code, 0);
  const Result r = run("offline --grid x", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--grid: 'x' is not an integer"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace studio::hull

// studio-tracker locate, run as a process on files written from the simulated studio: rig.yaml
// (core/yaml) and the true masks as PNG; the printed head must be the true one. Bad input must
// give a non-zero exit and one line on stderr.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <string>

#include "sim/cameras.h"
#include "sim/studio.h"
#include "yaml_io/rig_yaml.h"

namespace studio::tracker {
namespace {

namespace fs = std::filesystem;

struct Exec {
  int status;
  std::string out, err;
};

Exec run(const std::string& args) {
  const fs::path err =
      fs::temp_directory_path() / ("tracker_cli_err_" + std::to_string(::getpid()));
  const std::string cmd =
      std::string(STUDIO_BINARY_DIR) + "/tracker/studio-tracker " + args + " 2>" + err.string();
  Exec r;
  FILE* p = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
  r.status = ::pclose(p);
  FILE* e = std::fopen(err.string().c_str(), "r");
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), e)) r.err.append(buf.data(), n);
  std::fclose(e);
  fs::remove(err);
  return r;
}

class LocateCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("tracker_cli_" + std::to_string(::getpid())));
    fs::create_directories(*dir_ / "seq" / "000");
    fs::create_directories(*dir_ / "seq" / "001");
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::raise_hand;
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so).value();
    Rig rig;
    rig.cameras = studio.cameras();
    ASSERT_TRUE(yaml::write_rig(rig, (*dir_ / "rig.yaml").string()));
    for (int f : {0, 50}) {
      std::vector<Mask> masks;
      const auto truth = studio.render_all(f, nullptr, &masks);
      (f == 0 ? head0_ : head50_) = truth.head_centre();
      for (std::size_t c = 0; c < masks.size(); ++c) {
        const cv::Mat m(masks[c].height(), masks[c].width(), CV_8UC1, masks[c].data());
        const std::string name = rig.cameras[c].id + ".png";
        if (f == 50) cv::imwrite((*dir_ / name).string(), m);
        cv::imwrite((*dir_ / "seq" / (f == 0 ? "000" : "001") / name).string(), m);
      }
    }
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string base() {
    return "locate --rig " + (*dir_ / "rig.yaml").string() +
           " --box -1.6,0,-1.6,1.6,2.6,1.6 --grid 128";
  }
  static std::vector<Eigen::Vector3d> positions(const std::string& json) {
    std::vector<Eigen::Vector3d> out;
    const std::regex re(R"re("position": \[([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\])re");
    for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator();
         ++it)
      out.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]));
    return out;
  }
  static fs::path* dir_;
  static Eigen::Vector3d head0_, head50_;
};
fs::path* LocateCli::dir_ = nullptr;
Eigen::Vector3d LocateCli::head0_, LocateCli::head50_;

TEST_F(LocateCli, PrintsTheTrueHeadAsJson) {
  const Exec r = run(base() + " --masks " + dir_->string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"heads\": [", 0), 0u) << r.out;
  const auto p = positions(r.out);
  ASSERT_EQ(p.size(), 1u) << r.out;
  EXPECT_LT((p[0] - head50_).norm(), 0.03) << r.out;  // the hand is raised in frame 50
}

TEST_F(LocateCli, ASequenceGivesOneEntryPerFrame) {
  const Exec r = run(base() + " --masks " + (*dir_ / "seq").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto p = positions(r.out);
  ASSERT_EQ(p.size(), 2u) << r.out;
  EXPECT_LT((p[0] - head0_).norm(), 0.03);
  EXPECT_LT((p[1] - head50_).norm(), 0.03);
  EXPECT_NE(r.out.find("\"frame\": \"001\""), std::string::npos);
}

TEST_F(LocateCli, BadInputGivesOneLineAndNonZeroExit) {
  const std::string masks = " --masks " + dir_->string();
  for (const std::string& args :
       {std::string("locate --rig /nonexistent/rig.yaml --box 0,0,0,1,1,1 --grid 64") + masks,
        base() + masks + " --axis w", base() + " --masks /nonexistent",
        "locate --rig " + (*dir_ / "rig.yaml").string() + " --box 0,0,0,1,1 --grid 64" + masks,
        "locate --rig " + (*dir_ / "rig.yaml").string() + " --box 1,0,0,0,1,1 --grid 64" + masks,
        base() + masks + " --grid x", base() + masks + " --bogus 1", std::string("frobnicate")}) {
    const Exec r = run(args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
  EXPECT_EQ(run("--help").status, 0);
  EXPECT_EQ(run("locate --help").status, 0);
}

}  // namespace
}  // namespace studio::tracker

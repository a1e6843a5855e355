// studio-hull offline --take, run as a process on a take recorded from the simulated studio with
// the capture recorder (6 cameras, 352x288, frames 100..102): it keys every frame on the fly and
// writes the same meshes as the mask-folder route given the same keyer's masks; the meshes
// re-project onto the true masks; exact crossings (default) beat --no-refine; --frames, --timing
// and --progress work; a missing camera, a frame one camera lacks, a frame of the wrong size, a
// frame that fails its CRC, an empty box and a bad keyer file each give one clear error line.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "capture/recorder.h"
#include "core/rig.h"
#include "keyer/keyer.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "testing/mesh_read.h"
#include "testing/raster.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull {
namespace {

constexpr uint64_t kFirst = 100, kLast = 102;

struct Result {
  int code;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Result run(const std::string& args, const fs::path& dir) {
  const std::string cmd = std::string(STUDIO_HULL_CLI) + " " + args + " >" +
                          (dir / "out.txt").string() + " 2>" + (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  return {WEXITSTATUS(status), slurp(dir / "out.txt"), slurp(dir / "err.txt")};
}

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

void write_png(const Mask& m, const fs::path& path) {
  fs::create_directories(path.parent_path());
  cv::Mat img(m.height(), m.width(), CV_8U, const_cast<uint8_t*>(m.data()));
  ASSERT_TRUE(cv::imwrite(path.string(), img));
}

// Records frames [first, last] of camera `c` into take/<camera_id>, at the camera's size or at
// `width` x `height` when given (a wrongly configured camera).
// The take.yaml holds the camera's calibration, as the capture node writes it, unless
// `calibrated` is false.
void record(const sim::SimulatedStudio& studio, int c, const fs::path& take, uint64_t first,
            uint64_t last, int width = 0, int height = 0, bool calibrated = true) {
  const Camera& cam = studio.cameras()[std::size_t(c)];
  capture::TakeInfo info;
  info.take = take.filename().string();
  info.camera_id = cam.id;
  info.width = uint32_t(width ? width : cam.width);
  info.height = uint32_t(height ? height : cam.height);
  info.period_ns = 40'000'000;
  info.start_frame = first;
  if (calibrated) info.calibration_yaml = yaml::format_camera(cam, 2);
  auto rec = capture::Recorder::start({.dir = (take / cam.id).string(), .queue_frames = 16}, info);
  ASSERT_TRUE(rec) << rec.error().message;
  for (uint64_t f = first; f <= last; ++f) {
    Image<Rgb8> image;
    studio.render(c, int64_t(f), &image, nullptr);
    if (width) {  // a different sensor size: the top-left crop
      Image<Rgb8> crop(width, height);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) crop(x, y) = image(x, y);
      image = std::move(crop);
    }
    // The queue holds every frame of these short takes: push never drops here.
    ASSERT_TRUE((*rec)->push(f, int64_t(f) * 40'000'000, image.view()));
  }
  (*rec)->stop(last + 1);
  auto done = (*rec)->wait();
  ASSERT_TRUE(done) << done.error().message;
  ASSERT_EQ(done->frames, last - first + 1);
}

class HullCliTake : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("hull_cli_take_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    sim::RingOptions ring;
    ring.width = 352;
    ring.height = 288;
    ring.focal_px = 280;
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::walk;
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(ring), so);
    ASSERT_TRUE(studio) << studio.error().message;
    studio_ = new sim::SimulatedStudio(std::move(*studio));
    Rig rig;
    rig.cameras = studio_->cameras();
    ASSERT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()));
    // The take, and beside it the masks the same (default blue) keyer makes of its frames and
    // the true masks of the simulator.
    for (int c = 0; c < studio_->camera_count(); ++c) {
      record(*studio_, c, dir_ / "take", kFirst, kLast);
      auto keyer = keyer::Keyer::create({});
      ASSERT_TRUE(keyer);
      for (uint64_t f = kFirst; f <= kLast; ++f) {
        Image<Rgb8> image;
        Mask truth;
        studio_->render(c, int64_t(f), &image, &truth);
        RunMask keyed;
        ASSERT_TRUE(keyer->key(image.view(), keyed));
        const std::string name = std::to_string(f) + "/" + rig.cameras[std::size_t(c)].id + ".png";
        write_png(keyed.to_mask(), dir_ / "keyed" / name);
        write_png(truth, dir_ / "truth" / name);
      }
    }
  }
  static void TearDownTestSuite() {
    delete studio_;
    studio_ = nullptr;
    fs::remove_all(dir_);
  }

  static std::string base(const std::string& box = "-1.5,0,-1.5,1.5,2.2,1.5") {
    return "offline --rig " + (dir_ / "rig.yaml").string() + " --grid 128 --box " + box + " ";
  }
  // Worst IoU over the cameras of the mesh re-projected against the true mask of `frame`.
  static double worst_iou(const Mesh& mesh, uint64_t frame) {
    double worst = 1;
    for (int c = 0; c < studio_->camera_count(); ++c) {
      Mask truth;
      studio_->render(c, int64_t(frame), nullptr, &truth);
      const Camera& cam = studio_->cameras()[std::size_t(c)];
      worst = std::min(worst, testing::iou(testing::rasterise(mesh, cam), truth));
    }
    return worst;
  }

  static inline fs::path dir_;
  static inline sim::SimulatedStudio* studio_ = nullptr;
};

TEST_F(HullCliTake, KeysOnTheFlyAndMatchesTheMaskFolderRoute) {
  Result r = run(base() + "--take " + (dir_ / "take").string() + " --out " +
                     (dir_ / "from_take").string() + " --timing --progress",
                 dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  // JSON timing with every stage, keying included; the progress bar reached the end.
  for (const char* key :
       {"\"load\":", "\"key\":", "\"cut\":", "\"mesh\":", "\"refine\":", "\"write\":",
        "\"input\": \"take\"", "\"frames\": 3", "\"exact_crossings\": true"}) {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
  }
  EXPECT_NE(r.err.find("3/3 frames"), std::string::npos) << r.err;
  r = run(
      base() + "--masks " + (dir_ / "keyed").string() + " --out " + (dir_ / "from_keyed").string(),
      dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // no progress bar when stderr is not a terminal
  r = run(
      base() + "--masks " + (dir_ / "truth").string() + " --out " + (dir_ / "from_truth").string(),
      dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  for (uint64_t f = kFirst; f <= kLast; ++f) {
    const std::string name = std::to_string(f) + ".ply";
    auto take = testing::read_ply((dir_ / "from_take" / name).string());
    auto keyed = testing::read_ply((dir_ / "from_keyed" / name).string());
    auto truth = testing::read_ply((dir_ / "from_truth" / name).string());
    ASSERT_TRUE(take) << take.error().message;
    ASSERT_TRUE(keyed) << keyed.error().message;
    ASSERT_TRUE(truth) << truth.error().message;
    ASSERT_GT(take->triangles.size(), 1000u);
    EXPECT_TRUE(check_topology(*take).watertight());
    // Same keyer, same masks: the same mesh, to the float.
    ASSERT_EQ(take->vertices.size(), keyed->vertices.size());
    ASSERT_EQ(take->triangles.size(), keyed->triangles.size());
    float worst = 0;
    for (std::size_t k = 0; k < take->vertices.size(); ++k)
      worst = std::max(worst, (take->vertices[k] - keyed->vertices[k]).norm());
    EXPECT_LT(worst, 1e-6f) << name;
    // Keyed on the fly vs the simulator's true masks (at 352x288 the actor is ~70 px wide, so the
    // keyer's edge decisions, intersected over 6 views, move the volume by a few %; measured
    // +0.4 .. +1.4 % with edge refinement, 1.4 .. 6.7 % smaller before): volumes within 10 %, and
    // the keyed mesh re-projects onto the true masks (measured worst IoU 0.937-0.947, before
    // 0.917-0.948; the true masks' own mesh gives the ceiling, 0.942-0.952).
    const double vt = take->volume(), vs = truth->volume();
    const double iou = worst_iou(*take, f), ceiling = worst_iou(*truth, f);
    std::printf(
        "frame %lu: volume take %.4f truth %.4f m^3 (%+.2f %%), worst IoU vs true masks "
        "%.4f (true masks' mesh %.4f)\n",
        (unsigned long)f, vt, vs, 100 * (vt - vs) / vs, iou, ceiling);
    EXPECT_NEAR(vt, vs, 0.10 * vs) << name;
    EXPECT_GE(iou, 0.9) << name;
  }
}

TEST_F(HullCliTake, FramesSelectionSingleFileAndNoRefine) {
  Result r = run(base() + "--take " + (dir_ / "take").string() + " --frames 101:500 --out " +
                     (dir_ / "part").string() + " --format obj",
                 dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "part" / "100.obj"));
  EXPECT_TRUE(fs::exists(dir_ / "part" / "101.obj"));
  EXPECT_TRUE(fs::exists(dir_ / "part" / "102.obj"));
  // One selected frame and a mesh file name: that file. Refined (default) vs --no-refine.
  r = run(base() + "--take " + (dir_ / "take").string() + " --frames 101:101 --out " +
              (dir_ / "exact.ply").string(),
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(base() + "--take " + (dir_ / "take").string() + " --frames 101:101 --no-refine " +
              "--timing --out " + (dir_ / "plain.ply").string(),
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"exact_crossings\": false"), std::string::npos) << r.out;
  auto exact = testing::read_ply((dir_ / "exact.ply").string());
  auto plain = testing::read_ply((dir_ / "plain.ply").string());
  ASSERT_TRUE(exact && plain);
  ASSERT_EQ(exact->triangles.size(), plain->triangles.size());  // same topology
  const double iou_exact = worst_iou(*exact, 101), iou_plain = worst_iou(*plain, 101);
  std::printf("frame 101 at 128x128: worst IoU exact crossings %.4f, half-cell %.4f\n", iou_exact,
              iou_plain);
  EXPECT_GT(iou_exact, iou_plain);
  // Several frames into one mesh file.
  r = run(base() + "--take " + (dir_ / "take").string() + " --out " + (dir_ / "all.ply").string(),
          dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("names a mesh file but 3 frames are selected"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "all.ply"));
  // Nothing selected.
  r = run(base() + "--take " + (dir_ / "take").string() + " --frames 200:300 --out " +
              (dir_ / "none").string(),
          dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no recorded frames in --frames"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
}

TEST_F(HullCliTake, RejectsMissingCamera) {
  const fs::path take = dir_ / "take_missing";
  fs::copy(dir_ / "take", take, fs::copy_options::recursive);
  fs::remove_all(take / "cam2");
  Result r = run(base() + "--take " + take.string() + " --out " + (dir_ / "x").string(), dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no recording of camera cam2"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  // A camera that lacks one frame of the selection (a drop while recording).
  fs::remove_all(take);
  fs::copy(dir_ / "take", take, fs::copy_options::recursive);
  fs::remove_all(take / "cam4");
  record(*studio_, 4, take, kFirst, kLast - 1);
  r = run(base() + "--take " + take.string() + " --out " + (dir_ / "x").string(), dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("camera cam4 has no frame 102"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  // ... which --frames leaves out.
  r = run(base() + "--take " + take.string() + " --frames 100:101 --out " + (dir_ / "x").string(),
          dir_);
  EXPECT_EQ(r.code, 0) << r.err;
}

// Without --rig the cameras come from the calibration each camera recorded in its take.yaml:
// the same meshes as with the rig file. A camera recorded without calibration is one line that
// asks for a rig.
TEST_F(HullCliTake, WithoutARigUsesTheCalibrationRecordedInTheTake) {
  const std::string box = " --grid 128 --box -1.5,0,-1.5,1.5,2.2,1.5 --frames 101:101 ";
  Result r = run("offline --take " + (dir_ / "take").string() + box + "--out " +
                     (dir_ / "no_rig.ply").string(),
                 dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(base() + "--take " + (dir_ / "take").string() + " --frames 101:101 --out " +
              (dir_ / "with_rig.ply").string(),
          dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  auto a = testing::read_ply((dir_ / "no_rig.ply").string());
  auto b = testing::read_ply((dir_ / "with_rig.ply").string());
  ASSERT_TRUE(a && b);
  ASSERT_GT(a->triangles.size(), 1000u);
  ASSERT_EQ(a->triangles.size(), b->triangles.size());
  ASSERT_EQ(a->vertices.size(), b->vertices.size());
  float worst = 0;
  for (std::size_t k = 0; k < a->vertices.size(); ++k)
    worst = std::max(worst, (a->vertices[k] - b->vertices[k]).norm());
  EXPECT_LT(worst, 1e-6f);

  const fs::path take = dir_ / "take_uncalibrated";
  fs::copy(dir_ / "take", take, fs::copy_options::recursive);
  fs::remove_all(take / "cam3");
  record(*studio_, 3, take, kFirst, kLast, 0, 0, false);
  r = run("offline --take " + take.string() + box + "--out " + (dir_ / "x.ply").string(), dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cam3/take.yaml: camera recorded without calibration; give --rig"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  // Masks carry no calibration: a rig is required.
  r = run("offline --masks " + (dir_ / "keyed").string() + box + "--out " +
              (dir_ / "x.ply").string(),
          dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--rig is required with --masks"), std::string::npos) << r.err;
}

TEST_F(HullCliTake, RejectsFrameOfWrongSize) {
  const fs::path take = dir_ / "take_size";
  fs::copy(dir_ / "take", take, fs::copy_options::recursive);
  fs::remove_all(take / "cam1");
  record(*studio_, 1, take, kFirst, kLast, 320, 240);
  const Result r = run(
      base() + "--take " + take.string() + " --out " + (dir_ / "x").string() + " --progress", dir_);
  EXPECT_EQ(r.code, 1);
  // Frames load in parallel: whichever wrong frame is met first is named.
  EXPECT_TRUE(std::regex_search(r.err, std::regex("cam1: frame 10[0-2] is 320x240, camera cam1 is "
                                                  "352x288")))
      << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;  // no frame completes, so no progress bar either
}

TEST_F(HullCliTake, RejectsCorruptFrame) {
  const fs::path take = dir_ / "take_corrupt";
  fs::copy(dir_ / "take", take, fs::copy_options::recursive);
  {  // One payload byte of cam3's second frame (frames of 352x288 RGB8 follow 48-byte headers).
    std::fstream f(take / "cam3" / "frames.raw", std::ios::in | std::ios::out | std::ios::binary);
    const std::streamoff at = 48 + 352 * 288 * 3 + 48 + 1000;
    f.seekg(at);
    const char c = char(f.get() ^ 0x55);
    f.seekp(at);
    f.put(c);
  }
  const Result r =
      run(base() + "--take " + take.string() + " --threads 1 --out " + (dir_ / "x").string(), dir_);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("frame 101 fails its CRC"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
}

TEST_F(HullCliTake, RejectsEmptyBoxAndBadKeyer) {
  Result r = run(base("-1.5,0,-1.5,1.5,2.2,-1.5") + "--take " + (dir_ / "take").string() +
                     " --out " + (dir_ / "x").string(),
                 dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("box: empty along z"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  std::ofstream(dir_ / "keyer.yaml") << "keyer:\n  key: blue\n  clip_black: 90\n  clip_white: 50\n";
  r = run(base() + "--take " + (dir_ / "take").string() + " --keyer " +
              (dir_ / "keyer.yaml").string() + " --out " + (dir_ / "x").string(),
          dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("clip_white"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  r = run(base() + "--take " + (dir_ / "take").string() + " --key difference --out x", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--key: 'difference': expected blue or green"), std::string::npos) << r.err;
  r = run(base() + "--take " + (dir_ / "take").string() + " --masks " + dir_.string() + " --out x",
          dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("exactly one of --masks DIR or --take DIR"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace studio::hull

// studio-hull offline --take on a take of MOVING (Free-D tracked) cameras: the capture recorder
// writes each frame's calibration beside the frame (capture/take_calibration.h) and the offline
// hull cuts each frame with it. The meshes equal, to the float, those of one-frame takes recorded
// with that frame's poses as fixed calibration; without the per-frame calibration (the take.yaml
// pose of the first frame only) later frames come out different.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "capture/recorder.h"
#include "capture/take_calibration.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "testing/mesh_read.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull {
namespace {

constexpr uint64_t kFirst = 100, kLast = 102;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

struct Result {
  int code;
  std::string err;
};

Result run(const std::string& args, const fs::path& dir) {
  const std::string cmd = std::string(STUDIO_HULL_CLI) + " " + args + " >" +
                          (dir / "out.txt").string() + " 2>" + (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  return {WEXITSTATUS(status), slurp(dir / "err.txt")};
}

// The ring cameras at frame f: each swung about the studio's vertical axis by 8 degrees per
// frame, alternately left and right (a tracked camera on a pedestal moving round the actor).
std::vector<Camera> cameras_at(const std::vector<Camera>& ring, uint64_t f) {
  std::vector<Camera> out = ring;
  for (std::size_t c = 0; c < out.size(); ++c) {
    const double a = double(f - kFirst) * 8 * M_PI / 180 * (c % 2 ? 1 : -1);
    const Eigen::Matrix3d Ry = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
    // world_from_cam' = Ry * world_from_cam: R' = R Ry^T, t' = t.
    out[c].cam_from_world = Rigid3(Eigen::Matrix3d(ring[c].cam_from_world.R() * Ry.transpose()),
                                   ring[c].cam_from_world.translation);
  }
  return out;
}

// Records frames [first, last] of every camera into `take`, frame f rendered from cams[f]; the
// take.yaml calibration is cams[first]; `per_frame`: each frame's camera pushed with it.
void record(const std::map<uint64_t, std::vector<Camera>>& cams, const fs::path& take,
            uint64_t first, uint64_t last, bool per_frame, const sim::StudioOptions& so) {
  std::map<uint64_t, sim::SimulatedStudio> studios;
  for (uint64_t f = first; f <= last; ++f)
    studios.emplace(f, sim::SimulatedStudio::create(cams.at(f), so).value());
  for (std::size_t c = 0; c < cams.at(first).size(); ++c) {
    const Camera& cam = cams.at(first)[c];
    capture::TakeInfo info;
    info.take = take.filename().string();
    info.camera_id = cam.id;
    info.width = uint32_t(cam.width);
    info.height = uint32_t(cam.height);
    info.period_ns = 40'000'000;
    info.start_frame = first;
    info.calibration_yaml = yaml::format_camera(cam, 2);
    auto rec =
        capture::Recorder::start({.dir = (take / cam.id).string(), .queue_frames = 16}, info);
    ASSERT_TRUE(rec) << rec.error().message;
    for (uint64_t f = first; f <= last; ++f) {
      Image<Rgb8> image;
      studios.at(f).render(int(c), int64_t(f), &image, nullptr);
      std::optional<Camera> moved;
      if (per_frame) moved = cams.at(f)[c];
      ASSERT_TRUE((*rec)->push(f, int64_t(f) * 40'000'000, image.view(), moved));
    }
    (*rec)->stop(last + 1);
    auto done = (*rec)->wait();
    ASSERT_TRUE(done) << done.error().message;
  }
}

TEST(HullCliTrackedTake, PerFrameCalibrationMatchesFixedCalibrationOfTheSameFrames) {
  const fs::path dir =
      fs::temp_directory_path() / ("hull_tracked_take_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  sim::RingOptions ring;
  ring.width = 352;
  ring.height = 288;
  ring.focal_px = 280;
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::walk;
  std::map<uint64_t, std::vector<Camera>> cams;
  for (uint64_t f = kFirst; f <= kLast; ++f) cams[f] = cameras_at(sim::ring_cameras(ring), f);

  record(cams, dir / "moving", kFirst, kLast, true, so);
  record(cams, dir / "unmoved", kFirst, kLast, false, so);  // control: no per-frame calibration
  for (uint64_t f = kFirst; f <= kLast; ++f) {
    std::map<uint64_t, std::vector<Camera>> fixed{{f, cams[f]}};
    record(fixed, dir / ("fixed_" + std::to_string(f)), f, f, false, so);
  }
  // Each camera folder of the moving take holds one calibration line per frame.
  Camera base = cams[kFirst][0];
  auto lines = capture::read_take_calibration((dir / "moving" / base.id).string(), base);
  ASSERT_TRUE(lines) << lines.error().message;
  EXPECT_EQ(lines->size(), kLast - kFirst + 1);

  const std::string common = "offline --grid 128 --box -1.5,0,-1.5,1.5,2.2,1.5 ";
  Result r = run(
      common + "--take " + (dir / "moving").string() + " --out " + (dir / "out_moving").string(),
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(
      common + "--take " + (dir / "unmoved").string() + " --out " + (dir / "out_unmoved").string(),
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  for (uint64_t f = kFirst; f <= kLast; ++f) {
    r = run(common + "--take " + (dir / ("fixed_" + std::to_string(f))).string() + " --out " +
                (dir / ("out_fixed_" + std::to_string(f))).string(),
            dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string name = std::to_string(f) + ".ply";
    auto moving = testing::read_ply((dir / "out_moving" / name).string());
    auto fixed = testing::read_ply((dir / ("out_fixed_" + std::to_string(f)) / name).string());
    auto unmoved = testing::read_ply((dir / "out_unmoved" / name).string());
    ASSERT_TRUE(moving && fixed && unmoved);
    ASSERT_GT(moving->triangles.size(), 1000u);
    ASSERT_EQ(moving->vertices.size(), fixed->vertices.size()) << name;
    ASSERT_EQ(moving->triangles.size(), fixed->triangles.size()) << name;
    float worst = 0;
    for (std::size_t k = 0; k < moving->vertices.size(); ++k)
      worst = std::max(worst, (moving->vertices[k] - fixed->vertices[k]).norm());
    EXPECT_LT(worst, 1e-6f) << name;
    // The control: the first frame's poses for every frame are right only for the first frame.
    const double dv = std::abs(unmoved->volume() - fixed->volume()) / fixed->volume();
    std::printf("frame %lu: volume per-frame %.4f fixed %.4f first-pose-only %.4f m^3\n",
                (unsigned long)f, moving->volume(), fixed->volume(), unmoved->volume());
    if (f == kFirst)
      EXPECT_LT(dv, 1e-6);
    else
      EXPECT_GT(dv, 0.05) << name;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace studio::hull

// Projector calibration on a synthetic studio: a 1920x1080 projector with lens shift lights the
// back cloth and the floor in front of it, and a white board held in the beam at two positions
// (two more captures); 2-4 calibrated studio cameras see the projected 32x18 grid with 0.3 px
// detection noise. The solver must recover the projector's pose within 5 mm and 0.1
// degrees, its focal length within 0.5 % and the screen plane within a few millimetres; the result
// goes into rig.yaml through the rig writer and reads back.
#include "calibrate/projector_calibration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <random>

#include "core/rig.h"
#include "yaml_io/rig_yaml.h"

namespace studio::calibrate {
namespace {

constexpr double kWallZ = -2.0, kWallHalfWidth = 2.2, kWallTop = 2.6;

Rigid3 look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam;
  world_from_cam << x, y, z;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                            world_from_cam.transpose();
  return Rigid3(R, -R * centre);
}

Camera true_projector() {
  Camera p;
  p.id = "proj0";
  p.width = 1920;
  p.height = 1080;
  // Throw ratio ~1.3 at ~5.7 m, vertical lens shift (cy well below the centre row).
  p.intrinsics = Intrinsics{2500, 2500, 975, 610, 0};
  p.cam_from_world = look_at({0.3, 2.4, 3.5}, {0, 0.9, kWallZ}, 0.01);
  return p;
}

std::vector<Camera> studio_cameras(int n) {
  const Eigen::Vector3d positions[4] = {
      {-2.0, 1.8, 2.5}, {2.0, 1.5, 2.8}, {-1.0, 0.6, 3.0}, {1.5, 2.5, 1.5}};
  std::vector<Camera> out;
  for (int i = 0; i < n; ++i) {
    Camera c;
    c.id = "cam" + std::to_string(i);
    c.width = 704;
    c.height = 576;
    c.intrinsics = Intrinsics{700.0 + 20 * i, 700.0 + 20 * i, 352.0 + 3 * i, 288.0 - 2 * i, 0};
    c.distortion = Distortion::radial(-0.05, 0.01);
    c.cam_from_world = look_at(positions[i], {0, 0.8, -1.5}, 0.02 * i);
    out.push_back(c);
  }
  return out;
}

// The first surface the projector ray of `pixel` hits: the cloth (0) or the floor (1).
bool cast(const Camera& projector, const Eigen::Vector2d& pixel, Eigen::Vector3d* hit,
          int* surface) {
  const Eigen::Vector3d o = projector.centre_in_world();
  const Eigen::Vector3d d = projector.pixel_ray_in_world(pixel);
  double best = INFINITY;
  if (d.z() < 0) {
    const double l = (kWallZ - o.z()) / d.z();
    const Eigen::Vector3d x = o + l * d;
    if (l > 0 && x.y() >= 0 && x.y() <= kWallTop && std::abs(x.x()) <= kWallHalfWidth) {
      best = l;
      *hit = x;
      *surface = 0;
    }
  }
  if (d.y() < 0) {
    const double l = -o.y() / d.y();
    const Eigen::Vector3d x = o + l * d;
    if (l > 0 && l < best && x.z() >= kWallZ && std::abs(x.x()) <= 3.0) {
      best = l;
      *hit = x;
      *surface = 1;
    }
  }
  return std::isfinite(best);
}

// A white board held in the beam (surface 2, 3, ...): centre, unit normal (towards the
// projector), half sizes along its horizontal and vertical edges.
struct Board {
  Eigen::Vector3d centre;
  double yaw = 0;  // about +y, radians; the board faces +z when 0
  double half_width = 0.6, half_height = 0.45;
};

bool cast_board(const Camera& projector, const Eigen::Vector2d& pixel, const Board& b,
                Eigen::Vector3d* hit) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(b.yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d n = r * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d o = projector.centre_in_world();
  const Eigen::Vector3d d = projector.pixel_ray_in_world(pixel);
  if (std::abs(n.dot(d)) < 1e-6) return false;
  const double l = n.dot(b.centre - o) / n.dot(d);
  if (!(l > 0)) return false;
  const Eigen::Vector3d x = o + l * d;
  const Eigen::Vector3d local = r.transpose() * (x - b.centre);
  if (std::abs(local.x()) > b.half_width || std::abs(local.y()) > b.half_height) return false;
  *hit = x;
  return true;
}

struct Scenario {
  std::vector<Camera> cameras;
  Camera projector;
  std::vector<PatternFeature> features;
};

const std::vector<Board> kBoards = {{{-0.3, 1.4, 1.0}, 0.3}, {{0.6, 1.1, -0.5}, -0.25}};

struct ScenarioOptions {
  int cameras = 3;
  double noise_px = 0.3;
  unsigned seed = 1;
  bool wall_only = false;  // only the features on the cloth (no floor, no board)
  int cols = 32, rows = 18;
  std::vector<Board> boards = kBoards;
  Distortion projector_distortion;
};

Scenario make_scenario(const ScenarioOptions& o) {
  const int cameras = o.cameras, cols = o.cols, rows = o.rows;
  const bool wall_only = o.wall_only;
  const std::vector<Board>& boards = o.boards;
  Scenario s;
  s.cameras = studio_cameras(cameras);
  s.projector = true_projector();
  s.projector.distortion = o.projector_distortion;
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0, o.noise_px);
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      PatternFeature f;
      f.projector_pixel = {30 + i * (1860.0 / (cols - 1)), 30 + j * (1020.0 / (rows - 1))};
      Eigen::Vector3d x;
      if (!cast(s.projector, f.projector_pixel, &x, &f.surface)) continue;
      if (wall_only && f.surface != 0) continue;
      for (int c = 0; c < cameras; ++c) {
        Eigen::Vector2d p;
        if (!s.cameras[c].project(x, &p) || !s.cameras[c].in_image(p)) continue;
        f.views.push_back({c, p + Eigen::Vector2d(noise(rng), noise(rng))});
      }
      s.features.push_back(f);
    }
  }
  // One more capture per board position: the pattern features that fall on the board.
  for (size_t b = 0; b < boards.size() && !wall_only; ++b) {
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < cols; ++i) {
        PatternFeature f;
        f.projector_pixel = {30 + i * (1860.0 / (cols - 1)), 30 + j * (1020.0 / (rows - 1))};
        f.surface = 2 + static_cast<int>(b);
        Eigen::Vector3d x;
        if (!cast_board(s.projector, f.projector_pixel, boards[b], &x)) continue;
        for (int c = 0; c < cameras; ++c) {
          Eigen::Vector2d p;
          if (!s.cameras[c].project(x, &p) || !s.cameras[c].in_image(p)) continue;
          f.views.push_back({c, p + Eigen::Vector2d(noise(rng), noise(rng))});
        }
        s.features.push_back(f);
      }
    }
  }
  return s;
}

double rotation_error_deg(const Rigid3& a, const Rigid3& b) {
  return Eigen::AngleAxisd(a.rotation * b.rotation.conjugate()).angle() * 180 / M_PI;
}

TEST(ProjectorCalibration, RecoversPoseFocalAndScreenWithTwoToFourCameras) {
  for (int cameras = 2; cameras <= 4; ++cameras) {
    const Scenario s = make_scenario({.cameras = cameras, .seed = 100u + cameras});
    int on_floor = 0;
    for (const auto& f : s.features) on_floor += f.surface == 1;
    ASSERT_GT(on_floor, 20);
    ASSERT_GT(static_cast<int>(s.features.size()) - on_floor, 200);
    auto result = calibrate_projector(s.cameras, s.features, {});
    ASSERT_TRUE(result) << result.error().message;
    const Camera& got = result->projector.camera;
    const double position_mm = 1e3 * (got.centre_in_world() - s.projector.centre_in_world()).norm();
    const double rotation_deg = rotation_error_deg(got.cam_from_world, s.projector.cam_from_world);
    const double fx_rel = std::abs(got.intrinsics.fx / s.projector.intrinsics.fx - 1);
    const double fy_rel = std::abs(got.intrinsics.fy / s.projector.intrinsics.fy - 1);
    // Screen plane: distance of the true cloth's corners from the fitted plane.
    double plane_mm = 0;
    for (double x : {-kWallHalfWidth, kWallHalfWidth})
      for (double y : {0.0, kWallTop})
        plane_mm =
            std::max(plane_mm, 1e3 * std::abs(result->screen_plane.distance({x, y, kWallZ})));
    std::printf(
        "%d cameras: %d/%d features, triangulation %.3f px, projector %.3f px (DLT %.3f px, "
        "resection %.3f px, cameras %.3f px), "
        "position %.2f mm, rotation %.4f deg, fx %.3f %%, fy %.3f %%, cx %+.2f px, cy %+.2f px, "
        "plane %.2f mm (rms %.2f mm)\n",
        cameras, result->triangulated, result->features, result->triangulation_rms_px,
        result->rms_px, result->dlt_rms_px, result->resection_rms_px, result->camera_rms_px,
        position_mm, rotation_deg, 100 * fx_rel, 100 * fy_rel,
        got.intrinsics.cx - s.projector.intrinsics.cx,
        got.intrinsics.cy - s.projector.intrinsics.cy, plane_mm, 1e3 * result->plane_rms_m);
    EXPECT_LE(position_mm, 5.0) << cameras;
    EXPECT_LE(rotation_deg, 0.1) << cameras;
    EXPECT_LE(fx_rel, 0.005) << cameras;
    EXPECT_LE(fy_rel, 0.005) << cameras;
    EXPECT_LE(plane_mm, 3.0) << cameras;
    EXPECT_GT(result->screen_plane.normal.z(), 0.999);  // towards the projector
    // The screen rectangle from the features on the cloth lies on the cloth and is a valid screen.
    Rig rig;
    rig.cameras = s.cameras;
    store_projector(&rig, result->projector);
    EXPECT_TRUE(rig.validate()) << rig.validate().error().message;
    for (const auto& corner : result->projector.screen) {
      EXPECT_NEAR(corner.z(), kWallZ, 0.005);
      EXPECT_LE(std::abs(corner.x()), kWallHalfWidth + 0.01);
      EXPECT_GE(corner.y(), -0.01);
      EXPECT_LE(corner.y(), kWallTop + 0.01);
    }
  }
}

TEST(ProjectorCalibration, FitsRadialDistortionWhenAsked) {
  const Scenario s =
      make_scenario({.seed = 7, .projector_distortion = Distortion::radial(0.03, -0.01)});
  ProjectorCalibrationOptions options;
  auto plain = calibrate_projector(s.cameras, s.features, options);
  options.fit_radial = true;
  auto radial = calibrate_projector(s.cameras, s.features, options);
  ASSERT_TRUE(plain) << plain.error().message;
  ASSERT_TRUE(radial) << radial.error().message;
  const Camera& got = radial->projector.camera;
  EXPECT_LT(radial->rms_px, plain->rms_px);
  EXPECT_LE(1e3 * (got.centre_in_world() - s.projector.centre_in_world()).norm(), 5.0);
  EXPECT_LE(rotation_error_deg(got.cam_from_world, s.projector.cam_from_world), 0.1);
  EXPECT_LE(std::abs(got.intrinsics.fx / s.projector.intrinsics.fx - 1), 0.005);
  EXPECT_NEAR(got.distortion.rd3, 0.03, 0.01);
}

TEST(ProjectorCalibration, ResultGoesIntoRigYamlAndReadsBack) {
  const Scenario s = make_scenario({.seed = 21});
  ProjectorCalibrationOptions options;
  options.id = "proj_back";
  auto result = calibrate_projector(s.cameras, s.features, options);
  ASSERT_TRUE(result) << result.error().message;
  Rig rig;
  rig.cameras = s.cameras;
  Projector stale;
  stale.camera = s.projector;
  stale.camera.id = "proj_back";
  stale.screen = result->projector.screen;
  rig.projectors.push_back(stale);
  store_projector(&rig, result->projector);  // replaces the stale entry with the same id
  ASSERT_EQ(rig.projectors.size(), 1u);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("projector_calibration_test_" + std::to_string(::getpid()) + ".yaml"))
                               .string();
  ASSERT_TRUE(yaml::write_rig(rig, path));
  auto back = yaml::read_rig(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << back.error().message;
  const Projector* p = back->find_projector("proj_back");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->camera.intrinsics.fx, result->projector.camera.intrinsics.fx);
  EXPECT_EQ(p->camera.width, 1920);
  EXPECT_LE((p->camera.centre_in_world() - result->projector.camera.centre_in_world()).norm(),
            1e-9);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(p->screen[i], result->projector.screen[i]);
}

TEST(ProjectorCalibration, GivenCornersAreProjectedOntoTheFittedPlane) {
  const Scenario s = make_scenario({.seed = 5});
  ProjectorCalibrationOptions options;
  options.screen_corners = std::array<Eigen::Vector3d, 4>{
      Eigen::Vector3d(-2, 0, -1.95), Eigen::Vector3d(2, 0, -2.05), Eigen::Vector3d(2, 2.5, -1.97),
      Eigen::Vector3d(-2, 2.5, -2.02)};
  auto result = calibrate_projector(s.cameras, s.features, options);
  ASSERT_TRUE(result) << result.error().message;
  for (const auto& c : result->projector.screen) EXPECT_NEAR(c.z(), kWallZ, 0.003);
  EXPECT_NEAR(result->projector.screen[2].x(), 2, 0.01);
}

TEST(ProjectorCalibration, TriangulationIsExactOnExactData) {
  const std::vector<Camera> cameras = studio_cameras(3);
  const Eigen::Vector3d x(0.3, 1.1, -1.9);
  std::vector<PatternView> views;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector2d p;
    ASSERT_TRUE(cameras[c].project(x, &p));
    views.push_back({c, p});
  }
  auto dlt = triangulate_dlt(cameras, views);
  ASSERT_TRUE(dlt) << dlt.error().message;
  EXPECT_LE((*dlt - x).norm(), 1e-9);
  auto refined = refine_point(cameras, views, *dlt + Eigen::Vector3d(0.01, -0.01, 0.02));
  ASSERT_TRUE(refined);
  EXPECT_LE((refined->first - x).norm(), 1e-7);
  EXPECT_LE(refined->second, 1e-6);
  // Refusals: one view; two views of the same camera (parallel rays); an unknown camera.
  EXPECT_FALSE(triangulate_dlt(cameras, {views[0]}));
  EXPECT_FALSE(triangulate_dlt(cameras, {views[0], views[0]}));
  EXPECT_FALSE(triangulate_dlt(cameras, {views[0], {7, views[1].pixel}}));
}

TEST(ProjectorCalibration, RefusesPatternsOnOnePlaneAndBadInput) {
  // All features on the cloth: K and pose are not determined.
  const Scenario wall = make_scenario({.seed = 9, .wall_only = true});
  auto r = calibrate_projector(wall.cameras, wall.features, {});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("one plane"), std::string::npos) << r.error().message;
  // Positive control: the same setup with the floor features solves.
  const Scenario both = make_scenario({.seed = 9});
  EXPECT_TRUE(calibrate_projector(both.cameras, both.features, {}));
  // Too few features.
  std::vector<PatternFeature> few(both.features.begin(), both.features.begin() + 4);
  EXPECT_FALSE(calibrate_projector(both.cameras, few, {}));
  // A view of a camera that does not exist.
  std::vector<PatternFeature> bad = both.features;
  bad[3].views.push_back({9, {1, 1}});
  auto b = calibrate_projector(both.cameras, bad, {});
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("camera 9"), std::string::npos) << b.error().message;
  // No screen features (the screen surface id names nothing).
  ProjectorCalibrationOptions options;
  options.screen_surface = 5;
  EXPECT_FALSE(calibrate_projector(both.cameras, both.features, options));
  options = {};
  options.width = 0;
  EXPECT_FALSE(calibrate_projector(both.cameras, both.features, options));
}

}  // namespace
}  // namespace studio::calibrate

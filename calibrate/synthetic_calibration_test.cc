// The synthetic figures: 8 cameras, 12 frames, 100 points, 0.2 px noise.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "calibrate/camera_calibration.h"
#include "calibrate/geometry.h"
#include "calibrate/synthetic.h"

namespace studio::calibrate {
namespace {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

struct Errors {
  double centre_m = 0, focal_rel = 0, up_deg = 0, rotation_deg = 0, floor_deg = 0;
};

// The floor as the calibrated cameras see it: every point of the held-out floor frame (never
// in the solve) triangulated from its observed pixels with the estimated cameras, a plane
// fitted, and the angle of its normal to +y.
double floor_normal_deg(const Observations& obs, const std::vector<Camera>& cams) {
  std::vector<Eigen::Vector3d> points;
  for (const auto& f : obs.frames) {
    if (f.placement != Placement::floor || !f.holdout) continue;
    std::map<int, std::pair<std::vector<Camera>, std::vector<Eigen::Vector2d>>> rays;
    for (const auto& v : f.views)
      for (const auto& p : v.points) {
        rays[p.id].first.push_back(cams[obs.camera_index(v.camera_id)]);
        rays[p.id].second.push_back(p.pixel);
      }
    for (const auto& [id, r] : rays)
      if (r.first.size() >= 2)
        if (auto x = triangulate(r.first, r.second)) points.push_back(*x);
  }
  if (points.size() < 10) return NAN;  // no held-out floor frame seen by two cameras
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= points.size();
  Eigen::MatrixXd a(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) a.row(i) = (points[i] - mean).transpose();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  Eigen::Vector3d n = svd.matrixV().col(2);
  if (n.y() < 0) n = -n;
  return angle_deg(n, Eigen::Vector3d::UnitY());
}

// Worst camera errors against the truth, both in the studio frame.
Errors compare(const SyntheticStudio& s, const std::vector<Camera>& est) {
  const std::vector<Camera>& truth = s.cameras;
  Errors e;
  e.floor_deg = floor_normal_deg(s.observations, est);
  for (size_t i = 0; i < truth.size(); ++i) {
    e.centre_m = std::max(e.centre_m, (truth[i].centre_in_world() - est[i].centre_in_world()).norm());
    e.focal_rel = std::max(e.focal_rel, std::abs(est[i].intrinsics.fx / truth[i].intrinsics.fx - 1));
    e.focal_rel = std::max(e.focal_rel, std::abs(est[i].intrinsics.fy / truth[i].intrinsics.fy - 1));
    // The floor normal (+y) as each camera sees it.
    const Eigen::Vector3d up_true = truth[i].cam_from_world.rotation * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d up_est = est[i].cam_from_world.rotation * Eigen::Vector3d::UnitY();
    e.up_deg = std::max(e.up_deg, angle_deg(up_true, up_est));
    e.rotation_deg = std::max(
        e.rotation_deg,
        Eigen::AngleAxisd(truth[i].cam_from_world.rotation.conjugate() * est[i].cam_from_world.rotation)
                .angle() * 180 / M_PI);
  }
  return e;
}

TEST(SyntheticCalibration, EightCamerasTwelveFramesReachThePapersFigures) {
  SyntheticStudioOptions so;  // 8 cameras, 12 solved + 3 held-out frames, 0.2 px RMS noise
  const SyntheticStudio s = make_synthetic_studio(so);
  for (const Camera& c : s.cameras) {
    int views = 0;
    for (const auto& f : s.observations.frames)
      for (const auto& v : f.views) views += v.camera_id == c.id;
    ASSERT_GE(views, 3) << c.id;
  }
  CalibrationOptions o;
  auto r = calibrate_cameras(s.observations, s.target_points, o);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NEAR(r->rms_px, 0.2, 0.02);
  EXPECT_GT(r->heldout_observations, 0);
  EXPECT_LE(r->heldout_rms_px, 0.25);
  EXPECT_TRUE(r->outliers.size() <= 2) << r->outliers.size();  // Gaussian tails only
  const Errors e = compare(s, r->cameras);
  EXPECT_LT(e.centre_m, 0.005);
  EXPECT_LT(e.focal_rel, 0.002);
  EXPECT_LT(e.floor_deg, 0.05);
  RecordProperty("rms_px", std::to_string(r->rms_px));
  RecordProperty("heldout_rms_px", std::to_string(r->heldout_rms_px));
  std::printf("rms %.4f px, held-out %.4f px (%d obs), centre %.2f mm, focal %.4f %%, "
              "floor normal %.4f deg (per-camera up %.4f deg), rotation %.4f deg, %d iterations\n",
              r->rms_px, r->heldout_rms_px, r->heldout_observations, e.centre_m * 1000,
              e.focal_rel * 100, e.floor_deg, e.up_deg, e.rotation_deg, r->iterations);

  // Floor frames obey the parameterisation exactly: on y = 0, normal +y.
  for (const FrameStats& f : r->per_frame) {
    if (f.placement != Placement::floor) continue;
    EXPECT_EQ(f.world_from_target.translation.y(), 0.0);
    EXPECT_LT(angle_deg(f.world_from_target.rotation * Eigen::Vector3d::UnitZ(),
                        -Eigen::Vector3d::UnitY()), 1e-6);
  }
  // The solve's model is core/camera.h's: every inlier residual is Camera::project − observed.
  for (size_t i = 0; i < r->inliers.size(); i += 97) {
    const ScoredObservation& o = r->inliers[i];
    const int c = s.observations.camera_index(o.camera_id);
    const FrameStats* frame = nullptr;
    for (const auto& f : r->per_frame) if (f.id == o.frame_id) frame = &f;
    Eigen::Vector2d px;
    ASSERT_TRUE(r->cameras[c].project(frame->world_from_target * s.target_points[o.point], &px));
    EXPECT_NEAR((px - o.pixel - o.residual).norm(), 0, 1e-6);
  }
}

TEST(SyntheticCalibration, NoiseOfPointTwoPixelsPerAxisScalesTheErrors) {
  SyntheticStudioOptions so;
  so.noise_rms_px = 0.2 * std::sqrt(2.0);  // σ = 0.2 px on each of u and v
  so.seed = 7;
  const SyntheticStudio s = make_synthetic_studio(so);
  auto r = calibrate_cameras(s.observations, s.target_points, CalibrationOptions{});
  ASSERT_TRUE(r) << r.error().message;
  // Errors scale with the noise: the 0.2 px figures times √2.
  EXPECT_NEAR(r->rms_px, so.noise_rms_px, 0.1 * so.noise_rms_px);
  EXPECT_LE(r->heldout_rms_px, 0.25 * std::sqrt(2.0));
  const Errors e = compare(s, r->cameras);
  EXPECT_LT(e.centre_m, 0.005 * std::sqrt(2.0));
  EXPECT_LT(e.focal_rel, 0.002 * std::sqrt(2.0));
  EXPECT_LT(e.floor_deg, 0.05 * std::sqrt(2.0));
  std::printf("sigma 0.2/axis: rms %.4f px, held-out %.4f px, centre %.2f mm, focal %.4f %%, "
              "floor normal %.4f deg\n",
              r->rms_px, r->heldout_rms_px, e.centre_m * 1000, e.focal_rel * 100, e.floor_deg);
}

TEST(SyntheticCalibration, GrossOutliersAreReportedAndDropped) {
  SyntheticStudioOptions so;
  so.outliers = 25;
  so.seed = 3;
  const SyntheticStudio s = make_synthetic_studio(so);
  auto r = calibrate_cameras(s.observations, s.target_points, CalibrationOptions{});
  ASSERT_TRUE(r) << r.error().message;
  int gross = 0;
  for (const auto& o : r->outliers) gross += o.residual.norm() > 4;
  EXPECT_GE(gross, 20);  // 25 injected (a few may land on the same point or a held-out frame)
  EXPECT_LE(r->outliers.size(), 30u);
  EXPECT_NEAR(r->rms_px, 0.2, 0.02);
  const Errors e = compare(s, r->cameras);
  EXPECT_LT(e.centre_m, 0.005);
}

TEST(SyntheticCalibration, KFoldHeldOutRms) {
  SyntheticStudioOptions so;
  so.heldout_frames = 0;
  so.seed = 11;
  const SyntheticStudio s = make_synthetic_studio(so);
  CalibrationOptions o;
  o.k_fold = 3;
  auto r = calibrate_cameras(s.observations, s.target_points, o);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_GT(r->kfold_observations, 1000);
  EXPECT_LE(r->kfold_rms_px, 0.25);
  EXPECT_EQ(r->heldout_observations, 0);
}

TEST(SyntheticCalibration, FreeGaugePutsTheFirstCameraAtTheOrigin) {
  SyntheticStudioOptions so;
  so.seed = 5;
  SyntheticStudio s = make_synthetic_studio(so);
  for (auto& f : s.observations.frames) f.placement = Placement::free;
  auto r = calibrate_cameras(s.observations, s.target_points, CalibrationOptions{});
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NE(r->gauge.find("cam0"), std::string::npos);
  EXPECT_LT(r->cameras[0].cam_from_world.translation.norm(), 1e-12);
  // Relative geometry: the estimated centres rigidly aligned to the true ones (Kabsch; the
  // target spacing fixes the scale), so the gauge camera's own error is not counted n times.
  Eigen::Matrix3Xd a(3, s.cameras.size()), b(3, s.cameras.size());
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    a.col(i) = r->cameras[i].centre_in_world();
    b.col(i) = s.cameras[i].centre_in_world();
  }
  const Eigen::Matrix4d align = Eigen::umeyama(a, b, false);
  double worst = 0;
  for (size_t i = 0; i < s.cameras.size(); ++i)
    worst = std::max(worst, ((align * a.col(i).homogeneous()).head<3>() - b.col(i)).norm());
  EXPECT_LT(worst, 0.005);
}

TEST(SyntheticCalibration, ACameraSharingNoFrameIsNamed) {
  SyntheticStudio s = make_synthetic_studio(SyntheticStudioOptions{});
  // Move every view of cam7 into frames of its own.
  Observations obs = s.observations;
  std::vector<FrameObservations> lonely;
  for (auto& f : obs.frames) {
    for (auto it = f.views.begin(); it != f.views.end();) {
      if (it->camera_id == "cam7") {
        FrameObservations own;
        own.id = f.id + "_cam7";
        own.views.push_back(*it);
        lonely.push_back(own);
        it = f.views.erase(it);
      } else {
        ++it;
      }
    }
  }
  obs.frames.insert(obs.frames.end(), lonely.begin(), lonely.end());
  auto r = calibrate_cameras(obs, s.target_points, CalibrationOptions{});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("camera cam7 shares no frame"), std::string::npos)
      << r.error().message;
}

TEST(SyntheticCalibration, BadObservationsFailWithOneLine) {
  SyntheticStudio s = make_synthetic_studio(SyntheticStudioOptions{});
  Observations obs = s.observations;
  obs.frames[1].views[0].points[0].id = 100;
  auto r = calibrate_cameras(obs, s.target_points, CalibrationOptions{});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("point id 100"), std::string::npos) << r.error().message;
  obs = s.observations;
  obs.frames[1].placement = Placement::origin;
  r = calibrate_cameras(obs, s.target_points, CalibrationOptions{});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("more than one origin"), std::string::npos);
}

}  // namespace
}  // namespace studio::calibrate

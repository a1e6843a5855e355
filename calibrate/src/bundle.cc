// The one translation unit holding every Ceres cost function of the calibration (build time).
#include "calibrate/bundle.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include "calibrate/text.h"
#include <memory>

namespace studio::calibrate {
namespace {

// Intrinsics block layout.
enum { kF = 0, kAspect, kCx, kCy, kRd3, kRd5, kIntrinsicsSize };

// Pixel of a point in world coordinates: the model of bundle.h.
template <typename T>
bool project(const T* intrinsics, const T* cam_from_world, const T* x_world, T* pixel) {
  T x_cam[3];
  ceres::AngleAxisRotatePoint(cam_from_world, x_world, x_cam);
  x_cam[0] += cam_from_world[3];
  x_cam[1] += cam_from_world[4];
  x_cam[2] += cam_from_world[5];
  if (!(x_cam[2] > T(1e-9))) return false;
  const T x = x_cam[0] / x_cam[2];
  const T y = x_cam[1] / x_cam[2];
  const T r2 = x * x + y * y;
  const T radial = T(1) + r2 * (intrinsics[kRd3] + r2 * intrinsics[kRd5]);
  pixel[0] = intrinsics[kF] * radial * x + intrinsics[kCx];
  pixel[1] = intrinsics[kF] * intrinsics[kAspect] * radial * y + intrinsics[kCy];
  return true;
}

// Target point → world for the floor parameterisation [theta, tx, tz] (see floor_pose()).
template <typename T>
void floor_to_world(const T* floor, const Eigen::Vector3d& p, T* x_world) {
  const T c = cos(floor[0]), s = sin(floor[0]);
  x_world[0] = c * p.x() + s * p.y() + floor[1];
  x_world[1] = T(-p.z());
  x_world[2] = -s * p.x() + c * p.y() + floor[2];
}

struct FreeFrameCost {
  Eigen::Vector3d point;
  Eigen::Vector2d observed;
  template <typename T>
  bool operator()(const T* intrinsics, const T* cam, const T* frame, T* residual) const {
    const T p[3] = {T(point.x()), T(point.y()), T(point.z())};
    T x_world[3];
    ceres::AngleAxisRotatePoint(frame, p, x_world);
    for (int i = 0; i < 3; ++i) x_world[i] += frame[3 + i];
    T pixel[2];
    if (!project(intrinsics, cam, x_world, pixel)) return false;
    residual[0] = pixel[0] - observed.x();
    residual[1] = pixel[1] - observed.y();
    return true;
  }
};

struct FloorFrameCost {
  Eigen::Vector3d point;
  Eigen::Vector2d observed;
  template <typename T>
  bool operator()(const T* intrinsics, const T* cam, const T* floor, T* residual) const {
    T x_world[3];
    floor_to_world(floor, point, x_world);
    T pixel[2];
    if (!project(intrinsics, cam, x_world, pixel)) return false;
    residual[0] = pixel[0] - observed.x();
    residual[1] = pixel[1] - observed.y();
    return true;
  }
};

std::array<double, 6> pose_block(const Rigid3& pose) {
  const Eigen::AngleAxisd aa(pose.rotation);
  const Eigen::Vector3d v = aa.angle() * aa.axis();
  return {v.x(), v.y(), v.z(), pose.translation.x(), pose.translation.y(), pose.translation.z()};
}

Rigid3 pose_from_block(const double* b) {
  const Eigen::Vector3d v(b[0], b[1], b[2]);
  const double angle = v.norm();
  const Eigen::Quaterniond q =
      angle < 1e-15 ? Eigen::Quaterniond::Identity()
                    : Eigen::Quaterniond(Eigen::AngleAxisd(angle, v / angle));
  return Rigid3(q, Eigen::Vector3d(b[3], b[4], b[5]));
}

std::array<double, kIntrinsicsSize> intrinsics_block(const Camera& camera) {
  const Intrinsics& k = camera.intrinsics;
  double rd3 = 0, rd5 = 0;
  if (camera.distortion.model == Distortion::Model::radial) {
    rd3 = camera.distortion.rd3;
    rd5 = camera.distortion.rd5;
  } else if (camera.distortion.model == Distortion::Model::opencv) {
    rd3 = camera.distortion.k1;
    rd5 = camera.distortion.k2;
  }
  return {k.fx, k.fy / k.fx, k.cx, k.cy, rd3, rd5};
}

void store_intrinsics(const double* b, Camera* camera) {
  camera->intrinsics.fx = b[kF];
  camera->intrinsics.fy = b[kF] * b[kAspect];
  camera->intrinsics.cx = b[kCx];
  camera->intrinsics.cy = b[kCy];
  camera->intrinsics.skew = 0;
  camera->distortion = Distortion::radial(b[kRd3], b[kRd5]);
}

// All parameter blocks of one problem, owned here so Ceres can point into them.
struct State {
  std::vector<std::array<double, kIntrinsicsSize>> intrinsics;
  std::vector<std::array<double, 6>> cams;
  std::vector<std::array<double, 6>> frames;  // free: angle-axis + t; floor: theta, tx, tz
};

Eigen::Vector2d residual_of(const State& s, const std::vector<BundleFrame>& frames,
                            const Eigen::Vector3d& point, const BundleObservation& o) {
  double r[2] = {0, 0};
  bool ok;
  if (frames[o.frame].placement == Placement::floor) {
    ok = FloorFrameCost{point, o.pixel}(s.intrinsics[o.camera].data(), s.cams[o.camera].data(),
                                        s.frames[o.frame].data(), r);
  } else {
    ok = FreeFrameCost{point, o.pixel}(s.intrinsics[o.camera].data(), s.cams[o.camera].data(),
                                       s.frames[o.frame].data(), r);
  }
  if (!ok) return Eigen::Vector2d::Constant(1e6);  // behind the camera: as bad as it gets
  return {r[0], r[1]};
}

double rms_of(const State& s, const std::vector<BundleFrame>& frames,
              const std::vector<Eigen::Vector3d>& points,
              const std::vector<BundleObservation>& observations) {
  if (observations.empty()) return 0;
  double sum = 0;
  for (const auto& o : observations)
    sum += residual_of(s, frames, points[o.point], o).squaredNorm();
  return std::sqrt(sum / observations.size());
}

class ProgressCallback : public ceres::IterationCallback {
 public:
  ProgressCallback(std::function<void()> fn) : fn_(std::move(fn)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    fn_();
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<void()> fn_;
};

}  // namespace

Expected<void> BundleOptions::validate() const {
  if (!(loss_scale_px > 0)) return fail("bundle: loss_scale_px must be > 0");
  if (max_iterations < 1) return fail("bundle: max_iterations must be >= 1");
  if (threads < 1) return fail("bundle: threads must be >= 1");
  return {};
}

Rigid3 floor_pose(double theta, double tx, double tz) {
  // Columns: target x → studio x, target y → studio z, target z → studio −y; then about +y.
  Eigen::Matrix3d base;
  base << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return Rigid3(Eigen::Matrix3d(rot * base), Eigen::Vector3d(tx, 0, tz));
}

Eigen::Vector3d floor_parameters(const Rigid3& world_from_target) {
  Eigen::Matrix3d base;
  base << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  const Eigen::Matrix3d m = world_from_target.R() * base.transpose();  // ≈ R_y(theta)
  const double theta = std::atan2(m(0, 2) - m(2, 0), m(0, 0) + m(2, 2));
  return {theta, world_from_target.translation.x(), world_from_target.translation.z()};
}

Eigen::Vector2d reprojection_residual(const std::vector<Eigen::Vector3d>& target_points,
                                      const BundleObservation& o,
                                      const std::vector<BundleCamera>& cameras,
                                      const std::vector<BundleFrame>& frames) {
  State s;
  s.intrinsics.assign(cameras.size(), {});
  s.cams.assign(cameras.size(), {});
  s.frames.assign(frames.size(), {});
  s.intrinsics[o.camera] = intrinsics_block(cameras[o.camera].camera);
  s.cams[o.camera] = pose_block(cameras[o.camera].camera.cam_from_world);
  if (frames[o.frame].placement == Placement::floor) {
    const Eigen::Vector3d f = floor_parameters(frames[o.frame].world_from_target);
    s.frames[o.frame] = {f.x(), f.y(), f.z(), 0, 0, 0};
  } else {
    s.frames[o.frame] = pose_block(frames[o.frame].world_from_target);
  }
  return residual_of(s, frames, target_points[o.point], o);
}

Expected<BundleSummary> solve_bundle(const std::vector<Eigen::Vector3d>& target_points,
                                     const std::vector<BundleObservation>& observations,
                                     std::vector<BundleCamera>* cameras,
                                     std::vector<BundleFrame>* frames,
                                     const BundleOptions& options) {
  if (auto v = options.validate(); !v) return std::unexpected(v.error());
  const auto start = std::chrono::steady_clock::now();
  for (const auto& o : observations) {
    if (o.camera < 0 || o.camera >= static_cast<int>(cameras->size()) || o.frame < 0 ||
        o.frame >= static_cast<int>(frames->size()) || o.point < 0 ||
        o.point >= static_cast<int>(target_points.size()) || !o.pixel.allFinite())
      return fail("bundle: observation with an out-of-range camera, frame or point index");
  }
  State s;
  for (const auto& c : *cameras) {
    if (!(c.camera.intrinsics.fx > 0) || !(c.camera.intrinsics.fy > 0))
      return fail(format("bundle: camera {} has a non-positive focal length", c.camera.id));
    s.intrinsics.push_back(intrinsics_block(c.camera));
    s.cams.push_back(pose_block(c.camera.cam_from_world));
  }
  for (const auto& f : *frames) {
    if (f.placement == Placement::floor) {
      const Eigen::Vector3d p = floor_parameters(f.world_from_target);
      s.frames.push_back({p.x(), p.y(), p.z(), 0, 0, 0});
    } else {
      s.frames.push_back(pose_block(f.world_from_target));
    }
  }

  ceres::LossFunction* loss = nullptr;
  if (options.loss == BundleOptions::Loss::huber) loss = new ceres::HuberLoss(options.loss_scale_px);
  if (options.loss == BundleOptions::Loss::cauchy) loss = new ceres::CauchyLoss(options.loss_scale_px);
  // One loss object shared by all residual blocks: Ceres must not delete it more than once.
  std::unique_ptr<ceres::LossFunction> loss_owner(loss);
  ceres::Problem::Options shared_loss_options;
  shared_loss_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem shared(shared_loss_options);

  std::vector<bool> camera_used(cameras->size(), false), frame_used(frames->size(), false);
  for (const auto& o : observations) {
    const Eigen::Vector3d& p = target_points[o.point];
    double* intr = s.intrinsics[o.camera].data();
    double* cam = s.cams[o.camera].data();
    double* frame = s.frames[o.frame].data();
    if ((*frames)[o.frame].placement == Placement::floor) {
      shared.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FloorFrameCost, 2, kIntrinsicsSize, 6, 3>(
              new FloorFrameCost{p, o.pixel}),
          loss, intr, cam, frame);
    } else {
      shared.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FreeFrameCost, 2, kIntrinsicsSize, 6, 6>(
              new FreeFrameCost{p, o.pixel}),
          loss, intr, cam, frame);
    }
    camera_used[o.camera] = true;
    frame_used[o.frame] = true;
  }
  bool all_cameras_fixed = true;
  for (size_t i = 0; i < cameras->size(); ++i) {
    if (!camera_used[i]) continue;
    const BundleCamera& c = (*cameras)[i];
    if (c.fix_pose) shared.SetParameterBlockConstant(s.cams[i].data());
    else all_cameras_fixed = false;
    std::vector<int> fixed;
    if (c.fixed.focal) fixed.insert(fixed.end(), {kF, kAspect});
    else if (c.fixed.aspect) fixed.push_back(kAspect);
    if (c.fixed.principal_point) fixed.insert(fixed.end(), {kCx, kCy});
    if (c.fixed.rd3) fixed.push_back(kRd3);
    if (c.fixed.rd5) fixed.push_back(kRd5);
    if (fixed.size() == kIntrinsicsSize) {
      shared.SetParameterBlockConstant(s.intrinsics[i].data());
    } else if (!fixed.empty()) {
      all_cameras_fixed = false;
      shared.SetManifold(s.intrinsics[i].data(), new ceres::SubsetManifold(kIntrinsicsSize, fixed));
    } else {
      all_cameras_fixed = false;
    }
  }
  for (size_t i = 0; i < frames->size(); ++i)
    if (frame_used[i] && (*frames)[i].placement == Placement::origin)
      shared.SetParameterBlockConstant(s.frames[i].data());

  BundleSummary summary;
  summary.initial_rms_px = rms_of(s, *frames, target_points, observations);
  ceres::Solver::Options solver;
  solver.linear_solver_type = all_cameras_fixed ? ceres::DENSE_QR : ceres::DENSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.logging_type = ceres::SILENT;
  std::unique_ptr<ProgressCallback> callback;
  int iteration = 0;
  if (options.on_iteration) {
    solver.update_state_every_iteration = true;
    callback = std::make_unique<ProgressCallback>([&] {
      options.on_iteration(iteration++, rms_of(s, *frames, target_points, observations));
    });
    solver.callbacks.push_back(callback.get());
  }
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver, &shared, &ceres_summary);
  if (!ceres_summary.IsSolutionUsable())
    return fail("bundle: Ceres found no usable solution: " + ceres_summary.message);

  for (size_t i = 0; i < cameras->size(); ++i) {
    store_intrinsics(s.intrinsics[i].data(), &(*cameras)[i].camera);
    (*cameras)[i].camera.cam_from_world = pose_from_block(s.cams[i].data());
  }
  for (size_t i = 0; i < frames->size(); ++i) {
    BundleFrame& f = (*frames)[i];
    if (f.placement == Placement::floor)
      f.world_from_target = floor_pose(s.frames[i][0], s.frames[i][1], s.frames[i][2]);
    else if (f.placement == Placement::free)
      f.world_from_target = pose_from_block(s.frames[i].data());
  }
  summary.iterations = static_cast<int>(ceres_summary.iterations.size());
  summary.final_rms_px = rms_of(s, *frames, target_points, observations);
  summary.usable = true;
  summary.report = ceres_summary.BriefReport();
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace studio::calibrate

#include "projector/camera_clip.h"

namespace studio::projector {

Eigen::Matrix4d clip_from_world(const Camera& projector, double near_m, double far_m) {
  const Eigen::Matrix3d K = projector.intrinsics.K();
  const double W = projector.width, H = projector.height, n = near_m, f = far_m;
  Eigen::Matrix4d clip_from_cam = Eigen::Matrix4d::Zero();
  clip_from_cam(0, 0) = 2 * K(0, 0) / W;
  clip_from_cam(0, 1) = 2 * K(0, 1) / W;
  clip_from_cam(0, 2) = (2 * K(0, 2) + 1) / W - 1;
  clip_from_cam(1, 1) = -2 * K(1, 1) / H;
  clip_from_cam(1, 2) = 1 - (2 * K(1, 2) + 1) / H;
  clip_from_cam(2, 2) = (f + n) / (f - n);
  clip_from_cam(2, 3) = -2 * f * n / (f - n);
  clip_from_cam(3, 2) = 1;
  Eigen::Matrix4d cam_from_world = Eigen::Matrix4d::Identity();
  cam_from_world.topLeftCorner<3, 3>() = projector.cam_from_world.R();
  cam_from_world.topRightCorner<3, 1>() = projector.cam_from_world.translation;
  return clip_from_cam * cam_from_world;
}

}  // namespace studio::projector

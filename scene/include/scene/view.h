#pragma once
// Camera matrices in the OpenGL convention, used by the renderer, its callers and the tests that
// check a picture against the camera model.
//   cam_from_world = look_at(eye, at, up): the camera looks along its -z axis, x right, y up.
//   clip_from_cam  = perspective(fov_y, aspect, near, far): symmetric frustum, depth [-1, 1].
// The projector passes its own (off-axis) clip_from_cam; the renderer takes matrices as given.

#include <Eigen/Geometry>

namespace studio::scene {

Eigen::Matrix4d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& at,
                        const Eigen::Vector3d& up = Eigen::Vector3d::UnitY());
Eigen::Matrix4d perspective(double fov_y_rad, double aspect, double near_m, double far_m);

// Pixel position (x right, y down, origin at the top-left corner of the top-left pixel) of a
// world point under clip_from_world for a width x height image; `depth_ok` false when the point
// is behind the camera (w <= 0).
Eigen::Vector2d project_to_pixel(const Eigen::Matrix4d& clip_from_world,
                                 const Eigen::Vector3d& x_in_world, int width, int height,
                                 bool* depth_ok = nullptr);

}  // namespace studio::scene

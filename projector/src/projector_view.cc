#include "projector/projector_view.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "text.h"

namespace studio::projector {
namespace {

// Separating-axis test between the convex projected screen quad and the image rectangle.
bool quad_overlaps_image(const std::array<Eigen::Vector2d, 4>& quad, int width, int height) {
  const std::array<Eigen::Vector2d, 4> image = {
      Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(width - 0.5, -0.5),
      Eigen::Vector2d(width - 0.5, height - 0.5), Eigen::Vector2d(-0.5, height - 0.5)};
  std::vector<Eigen::Vector2d> axes = {Eigen::Vector2d::UnitX(), Eigen::Vector2d::UnitY()};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d e = quad[(i + 1) % 4] - quad[i];
    axes.emplace_back(-e.y(), e.x());
  }
  for (const Eigen::Vector2d& axis : axes) {
    double qmin = INFINITY, qmax = -INFINITY, imin = INFINITY, imax = -INFINITY;
    for (const auto& p : quad) {
      qmin = std::min(qmin, axis.dot(p));
      qmax = std::max(qmax, axis.dot(p));
    }
    for (const auto& p : image) {
      imin = std::min(imin, axis.dot(p));
      imax = std::max(imax, axis.dot(p));
    }
    if (qmax < imin || imax < qmin) return false;
  }
  return true;
}

// NDC of the eye's off-axis view -> screen coordinates (metres).
Eigen::Matrix3d screen_from_eye_ndc(const Screen& s) {
  Eigen::Matrix3d m;
  m << s.width / 2, 0, s.width / 2, 0, s.height / 2, s.height / 2, 0, 0, 1;
  return m;
}

Eigen::Matrix3d texture_from_screen(const Screen& s) {
  return Eigen::Vector3d(1 / s.width, 1 / s.height, 1).asDiagonal();
}

}  // namespace

Eigen::Matrix3d ndc_from_pixel(int width, int height) {
  Eigen::Matrix3d m;
  m << 2.0 / width, 0, 1.0 / width - 1, 0, -2.0 / height, 1 - 1.0 / height, 0, 0, 1;
  return m;
}

Eigen::Matrix3d pixel_from_ndc(int width, int height) {
  Eigen::Matrix3d m;
  m << width / 2.0, 0, width / 2.0 - 0.5, 0, -height / 2.0, height / 2.0 - 0.5, 0, 0, 1;
  return m;
}

Expected<ProjectorView> ProjectorView::create(const Projector& projector,
                                              const ScreenOptions& screen_options) {
  const Camera& cam = projector.camera;
  const std::string who = "projector " + (cam.id.empty() ? std::string("(no id)") : cam.id);
  if (auto v = validate_camera(cam, who); !v) return std::unexpected(v.error());
  auto screen = Screen::from_corners(projector.screen, screen_options);
  if (!screen) return fail(who + ": " + screen.error().message);

  ProjectorView view;
  view.camera_ = cam;
  view.screen_ = *screen;
  const Screen& s = view.screen_;
  if (!(s.signed_distance(cam.centre_in_world()) > 0)) {
    return fail(who +
                ": does not see its screen: the projector is behind the screen plane (it would "
                "light the back of the cloth)");
  }
  const std::array<Eigen::Vector3d, 4> corners = s.corners();
  std::array<Eigen::Vector2d, 4> projected;
  const double scale = std::max(s.width, s.height);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d x = cam.cam_from_world * corners[i];
    if (!(x.z() > 1e-6 * scale)) {
      return fail(who + ": does not see its screen: a screen corner is behind the projector");
    }
    projected[i] = (cam.intrinsics.K() * x).hnormalized();
  }
  if (!quad_overlaps_image(projected, cam.width, cam.height))
    return fail(who + ": does not see its screen: the screen lies outside the projector image");

  const Eigen::Matrix3d R = cam.cam_from_world.R();
  Eigen::Matrix3d rt;
  rt.col(0) = R * s.right;
  rt.col(1) = R * s.up;
  rt.col(2) = cam.cam_from_world * s.origin;
  view.pixel_from_screen_ = cam.intrinsics.K() * rt;
  view.screen_from_pixel_ = view.pixel_from_screen_.inverse();
  if (!view.screen_from_pixel_.allFinite())
    return fail(who + ": does not see its screen: the screen plane passes through the projector");
  return view;
}

Eigen::Vector2d ProjectorView::screen_from_observed_pixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Matrix3d K = camera_.intrinsics.K();
  const Eigen::Vector2d observed = (K.inverse() * pixel.homogeneous()).hnormalized();
  const Eigen::Vector2d ideal = undistort(camera_.distortion, observed);
  return (screen_from_pixel_ * K * ideal.homogeneous()).hnormalized();
}

std::vector<float> ProjectorView::warp_map() const {
  const int w = camera_.width, h = camera_.height;
  std::vector<float> map(2 * static_cast<size_t>(w) * h);
  const Eigen::Matrix3d K = camera_.intrinsics.K();
  const Eigen::Matrix3d K_inv = K.inverse();
  const Eigen::Matrix3d tex_from_ideal_norm = texture_from_screen(screen_) * screen_from_pixel_ * K;
  const bool identity = camera_.distortion.is_identity();
  size_t i = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      Eigen::Vector2d n = (K_inv * Eigen::Vector3d(u, v, 1)).hnormalized();
      if (!identity) n = undistort(camera_.distortion, n);
      const Eigen::Vector2d t = (tex_from_ideal_norm * n.homogeneous()).hnormalized();
      map[i++] = static_cast<float>(t.x());
      map[i++] = static_cast<float>(t.y());
    }
  }
  return map;
}

Eigen::Vector2i ProjectorView::suggested_texture_size() const {
  const std::array<Eigen::Vector3d, 4> c = screen_.corners();
  std::array<Eigen::Vector2d, 4> p;
  for (int i = 0; i < 4; ++i)
    p[i] = (pixel_from_screen_ * screen_.coordinates(c[i]).homogeneous()).hnormalized();
  const double along_width = std::max((p[1] - p[0]).norm(), (p[2] - p[3]).norm());
  const double along_height = std::max((p[3] - p[0]).norm(), (p[2] - p[1]).norm());
  return {std::max(1, static_cast<int>(std::ceil(along_width))),
          std::max(1, static_cast<int>(std::ceil(along_height)))};
}

Expected<SinglePass> ProjectorView::single_pass(const Eigen::Vector3d& eye,
                                                const OffAxisOptions& options) const {
  if (!camera_.distortion.is_identity()) {
    return fail("projector " + camera_.id +
                ": has lens distortion, which the single-pass form cannot fold into a matrix: use "
                "the two-pass form");
  }
  auto eye_view = off_axis_view(screen_, eye, options);
  if (!eye_view) return std::unexpected(eye_view.error());
  SinglePass out;
  out.eye = *eye_view;
  Eigen::Matrix3d g = ndc_from_pixel(camera_.width, camera_.height) * pixel_from_screen_ *
                      screen_from_eye_ndc(screen_);
  // k(x, y) = g.row(2) . (x, y, 1) is affine in the eye's NDC: its extremes on the screen
  // rectangle are at the corners. Positive there (every corner in front of the projector, checked
  // in create()); scale so that its minimum is 1.
  double kmin = INFINITY;
  for (double x : {-1.0, 1.0})
    for (double y : {-1.0, 1.0}) kmin = std::min(kmin, g.row(2).dot(Eigen::Vector3d(x, y, 1)));
  if (!(kmin > 0)) return fail("projector " + camera_.id + ": does not see its screen");
  g /= kmin;
  const Eigen::Matrix4d& e = out.eye.clip_from_world;
  Eigen::Matrix<double, 3, 4> xyw;
  xyw.row(0) = e.row(0);
  xyw.row(1) = e.row(1);
  xyw.row(2) = e.row(3);
  const Eigen::Matrix<double, 3, 4> folded = g * xyw;
  out.clip_from_world.row(0) = folded.row(0);
  out.clip_from_world.row(1) = folded.row(1);
  out.clip_from_world.row(2) = e.row(2);
  out.clip_from_world.row(3) = folded.row(2);
  // Near plane of the eye: view z <= -near, i.e. -(vn . (x - eye)) - near >= 0.
  out.eye_clip_plane.head<3>() = -screen_.normal;
  out.eye_clip_plane(3) = screen_.normal.dot(eye) - options.near_m;
  return out;
}

Expected<TwoPass> ProjectorView::two_pass(const Eigen::Vector3d& eye,
                                          const OffAxisOptions& options) const {
  auto eye_view = off_axis_view(screen_, eye, options);
  if (!eye_view) return std::unexpected(eye_view.error());
  TwoPass out;
  out.eye = *eye_view;
  out.texture_from_pixel = texture_from_screen(screen_) * screen_from_pixel_;
  out.pixel_from_texture = out.texture_from_pixel.inverse();
  out.texture_from_ndc = out.texture_from_pixel * pixel_from_ndc(camera_.width, camera_.height);
  Eigen::Matrix3d pixel_from_fragcoord;  // u = x - 0.5, v = H - 0.5 - y
  pixel_from_fragcoord << 1, 0, -0.5, 0, -1, camera_.height - 0.5, 0, 0, 1;
  out.texture_from_fragcoord = out.texture_from_pixel * pixel_from_fragcoord;
  out.exact = camera_.distortion.is_identity();
  return out;
}

}  // namespace studio::projector

// Projector light truth (sim/projector_light.h) against independent checks: the simulated
// studio's own camera renderer (render.cc's per-camera ray casting), the core camera model's
// projection, analytic wall intersections, and finite differences of the actor's motion.
#include "sim/projector_light.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/look_at.h"
#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::sim {
namespace {

Camera camera_at(const std::string& id, const Eigen::Vector3d& centre,
                 const Eigen::Vector3d& target, int w, int h, double f) {
  Camera c;
  c.id = id;
  c.width = w;
  c.height = h;
  c.intrinsics.fx = c.intrinsics.fy = f;
  c.intrinsics.cx = 0.5 * (w - 1);
  c.intrinsics.cy = 0.5 * (h - 1);
  c.cam_from_world = look_at(centre, target);
  return c;
}

Image<Rgb8> checker(int w, int h, int square) {
  Image<Rgb8> img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool white = ((x / square) + (y / square)) % 2 == 0;
      img(x, y) = white ? Rgb8{250, 240, 230} : Rgb8{10, 20, 30};
    }
  return img;
}

Actor::Options swing_actor() {
  Actor::Options a;
  a.motion = Motion::arm_swing;
  a.seed = 3;
  return a;
}

// (b) The projector's actor mask equals what the studio's camera renderer (an independent ray
// caster: per-part camera-frame intersection in render.cc) draws as the true mask of a camera
// with the projector's calibration.
TEST(ProjectorLight, ActorMaskMatchesTheStudioRendererOfTheSameCamera) {
  const Cyclorama cyc;
  const Projector proj = studio_projector(cyc, {0.4, 2.4, 3.6}, 6.0, 960, 540);
  StudioOptions so;
  so.actor = swing_actor();
  so.noise_sigma = 0;
  auto studio = SimulatedStudio::create({proj.camera}, so);
  ASSERT_TRUE(studio) << studio.error().message;
  for (int64_t frame : {0, 7, 19}) {
    Mask rendered;
    studio->render(0, frame, nullptr, &rendered);
    const Mask mine = actor_in_projector(proj.camera, studio->truth(frame).body);
    int64_t both = 0, either = 0;
    for (std::size_t i = 0; i < mine.pixels().size(); ++i) {
      both += mine.pixels()[i] && rendered.pixels()[i];
      either += mine.pixels()[i] || rendered.pixels()[i];
    }
    ASSERT_GT(both, 2000) << "the actor must be in the beam";
    EXPECT_LE(either - both, 2) << "frame " << frame;  // ties at grazing rays only
  }
}

TEST(ProjectorLight, ActorAtDisplayIsTheActorLagLater) {
  const Actor actor(swing_actor());
  // A projector beside the swing plane (the hand's velocity across its image).
  const Eigen::Vector3d hand0 = actor.body_at(0).part(PartId::hand_r).centre;
  const Eigen::Vector3d vel = (actor.body_at(0.01).part(PartId::hand_r).centre - hand0) / 0.01;
  const Eigen::Vector3d side = vel.cross(Eigen::Vector3d::UnitY()).normalized();
  Projector proj;
  proj.camera =
      camera_at("proj0", hand0 + 4 * side + Eigen::Vector3d(0, 1, 0), hand0, 640, 360, 900);
  DisplayOptions d;
  d.display_lag_s = 0.04;
  const double t = 0;  // the arm passes its lowest point at full speed
  const Mask shown = actor_at_display(actor, proj.camera, t, d);
  EXPECT_EQ(shown.pixels(), actor_in_projector(proj.camera, actor.body_at(t + 0.04)).pixels());
  // The swinging arm moves several pixels in 40 ms: the lag matters.
  const Mask rendered = actor_in_projector(proj.camera, actor.body_at(t));
  int differ = 0;
  for (std::size_t i = 0; i < shown.pixels().size(); ++i)
    differ += shown.pixels()[i] != rendered.pixels()[i];
  EXPECT_GT(differ, 50);
  d.display_lag_s = 0;
  EXPECT_FALSE(d.validate());
  EXPECT_THROW(actor_at_display(actor, proj.camera, t, d), std::invalid_argument);
  d.display_lag_s = 0.016;
  EXPECT_TRUE(d.validate());
}

TEST(ProjectorLight, CountLitAgainstAPixelLoop) {
  Mask actor(40, 10, 0);
  for (int y = 2; y < 8; ++y)
    for (int x = 10; x < 25; ++x) actor(x, y) = 255;
  Mask black(40, 10, 0);
  for (int y = 0; y < 10; ++y)
    for (int x = 5; x < 20; ++x) black(x, y) = 255;
  black(30, 4) = 255;
  const LitCount c = count_lit(actor, RunMask::from_mask(black.view()));
  uint64_t lit = 0, wasted = 0, a = 0, b = 0;
  for (std::size_t i = 0; i < actor.pixels().size(); ++i) {
    a += actor.pixels()[i] != 0;
    b += black.pixels()[i] != 0;
    lit += actor.pixels()[i] && !black.pixels()[i];
    wasted += !actor.pixels()[i] && black.pixels()[i];
  }
  EXPECT_EQ(c.actor, a);
  EXPECT_EQ(c.blackout, b);
  EXPECT_EQ(c.lit_actor, lit);
  EXPECT_EQ(c.wasted, wasted);
  EXPECT_EQ(lit, 6u * 5u);
  EXPECT_EQ(count_lit(actor, RunMask::from_mask(actor.view())).lit_actor, 0u);
  EXPECT_THROW(count_lit(actor, RunMask(39, 10)), std::invalid_argument);
}

// (a) From the projector's own centre with its own intrinsics, the eye sees the frame unchanged
// (every pixel's ray meets the cloth exactly where that projector pixel lights it); from another
// eye, a lit block lands where the analytic wall point of its centre projects (core camera).
TEST(ProjectorLight, EyeViewReproducesTheFrameAndItsGeometry) {
  const Cyclorama cyc;
  Projector proj = studio_projector(cyc, {0.0, 2.2, 3.0}, 5.0, 320, 180);
  ProjectorLight light;
  light.samples = 1;
  light.projectors.push_back({proj, checker(320, 180, 16)});
  ASSERT_TRUE(light.validate());
  const EyeView same = eye_view(light, cyc, proj.camera);
  int equal = 0, lit = 0;
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 320; ++x) {
      lit += same.lit(x, y) != 0;
      const Rgb8 a = same.image(x, y), b = light.projectors[0].frame(x, y);
      equal += a.r == b.r && a.g == b.g && a.b == b.b;
    }
  EXPECT_EQ(equal, 320 * 180);
  EXPECT_EQ(lit, 320 * 180);

  // A single bright block around projector pixel (200, 60), seen by an eye at head height.
  Image<Rgb8> frame(320, 180, Rgb8{0, 0, 0});
  for (int y = 58; y <= 62; ++y)
    for (int x = 198; x <= 202; ++x) frame(x, y) = {255, 255, 255};
  light.projectors[0].frame = frame;
  light.samples = 3;
  const Camera eye = camera_at("eye", {0.5, 1.65, 0.8}, {0, 1.6, -4.5}, 640, 480, 500);
  const EyeView seen = eye_view(light, cyc, eye);
  const Eigen::Vector3d d = proj.camera.pixel_ray_in_world({200, 60});
  const Eigen::Vector3d C = proj.camera.centre_in_world();
  const Eigen::Vector3d wall = C + ((-cyc.half_width - C.z()) / d.z()) * d;
  Eigen::Vector2d expected;
  ASSERT_TRUE(eye.project(wall, &expected));
  double sx = 0, sy = 0, sw = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      const double w = seen.image(x, y).g;
      sx += w * x;
      sy += w * y;
      sw += w;
    }
  ASSERT_GT(sw, 0);
  EXPECT_NEAR(sx / sw, expected.x(), 0.3);
  EXPECT_NEAR(sy / sw, expected.y(), 0.3);
  // The actor standing in the beam shadows the cloth behind it.
  const Actor actor(Actor::Options{});
  light.projectors[0].frame = Image<Rgb8>(320, 180, Rgb8{200, 200, 200});
  light.samples = 1;
  const ActorBody body = actor.body_at(0);
  const EyeView free = eye_view(light, cyc, eye), shadowed = eye_view(light, cyc, eye, &body);
  int darker = 0;
  for (std::size_t i = 0; i < free.lit.pixels().size(); ++i)
    darker += free.lit.pixels()[i] && !shadowed.lit.pixels()[i];
  EXPECT_GT(darker, 100);
}

// (c) The studio cameras: the cloth adds cloth_gain x exposure of the projector's light to the
// ring light's blue; normal settings keep the cloth keyable, ring off + long exposure shows the
// pattern with high contrast; a board in the beam is lit and shadows the cloth behind it.
TEST(ProjectorLight, CamerasSeeTheDimmedPatternOnTheCloth) {
  const Cyclorama cyc;
  const Projector proj = studio_projector(cyc, {0.0, 2.4, 3.2}, 6.0, 480, 270);
  RingOptions ro;
  ro.count = 4;
  ro.overhead = false;
  ro.first_azimuth_deg = 30;
  ro.width = 352;
  ro.height = 288;
  ro.focal_px = 280;
  StudioOptions plain;
  plain.noise_sigma = 0;
  auto base = SimulatedStudio::create(ring_cameras(ro), plain);
  ASSERT_TRUE(base);
  StudioOptions lit = plain;
  lit.projector_light.projectors.push_back({proj, Image<Rgb8>(480, 270, Rgb8{255, 255, 255})});
  auto on = SimulatedStudio::create(ring_cameras(ro), lit);
  ASSERT_TRUE(on) << on.error().message;
  // Camera 0 (azimuth 30 deg, looking across at the back wall): pixels on the screen rectangle.
  const Camera& cam = base->cameras()[0];
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.project(Eigen::Vector3d(0, 1.6, -cyc.half_width), &px));
  const Rgb8 a = base->background(0)(int(px.x()), int(px.y()));
  const Rgb8 b = on->background(0)(int(px.x()), int(px.y()));
  EXPECT_NEAR(b.r - a.r, 0.12 * 255, 1.5);
  EXPECT_NEAR(b.b - std::min<int>(a.b, 255), std::min(255.0, a.b + 0.12 * 255) - a.b, 1.5);
  EXPECT_GT(b.b, b.r + 60);  // still keyable blue
  // Ring off, exposure 4: a checker pattern shows with contrast far above the noise.
  StudioOptions cal = plain;
  cal.projector_light.ring_level = 0;
  cal.projector_light.exposure = 4;
  cal.projector_light.projectors.push_back({proj, checker(480, 270, 30)});
  Board board;
  board.centre = Eigen::Vector3d(0.3, 1.5, -1.0);
  board.x_axis = Eigen::Vector3d::UnitX();
  board.y_axis = Eigen::Vector3d::UnitY();
  cal.projector_light.boards.push_back(board);
  auto dark = SimulatedStudio::create(ring_cameras(ro), cal);
  ASSERT_TRUE(dark) << dark.error().message;
  int hi = 0, lo = 0;
  for (int y = 0; y < 288; ++y)
    for (int x = 0; x < 352; ++x) {
      const Rgb8 c = dark->background(0)(x, y);
      hi += c.g > 100;
      lo += c.g < 10;
    }
  EXPECT_GT(hi, 3000);
  EXPECT_GT(lo, 3000);
  // The board: camera pixel of its centre sees the board's albedo-weighted light; the cloth point
  // behind the board, on the projector's ray, receives nothing.
  ASSERT_TRUE(cam.project(board.centre + Eigen::Vector3d(0.01, 0.01, 0), &px));
  const Eigen::Vector2i q(int(std::lround(px.x())), int(std::lround(px.y())));
  const auto on_board = hit_surface(cyc, cal.projector_light.boards, cam.centre_in_world(),
                                    cam.pixel_ray_in_world(q.cast<double>()));
  ASSERT_TRUE(on_board);
  ASSERT_EQ(on_board->board, 0);
  const double l = projected_light(cal.projector_light, on_board->point, 0)[0];
  const double expect = std::min(255.0, 4 * (0.12 * 0.85 * 255 + 0.7 * 0.85 * l));
  EXPECT_NEAR(dark->background(0)(q.x(), q.y()).r, expect, 3);
  const Eigen::Vector3d P = proj.camera.centre_in_world();
  const Eigen::Vector3d dir = (board.centre - P).normalized();
  const Eigen::Vector3d behind = P + ((-cyc.half_width - P.z()) / dir.z()) * dir;
  const auto shade = projected_light(cal.projector_light, behind, -1);
  EXPECT_EQ(shade[0] + shade[1] + shade[2], 0);
  StudioOptions no_board = cal;
  no_board.projector_light.boards.clear();
  const auto open = projected_light(no_board.projector_light, behind, -1);
  EXPECT_GT(open[0] + open[1] + open[2], 0);
}

TEST(ProjectorLight, RefusesWhatItDoesNotModel) {
  const Cyclorama cyc;
  ProjectorLight light;
  Projector proj = studio_projector(cyc, {0, 2.4, 3.2});
  light.projectors.push_back({proj, Image<Rgb8>(10, 10)});
  EXPECT_FALSE(light.validate());  // frame size differs
  light.projectors[0].frame = Image<Rgb8>();
  EXPECT_TRUE(light.validate());
  light.projectors[0].projector.camera.distortion = Distortion::radial(0.1, 0);
  EXPECT_FALSE(light.validate());
  light.projectors[0].projector.camera.distortion = Distortion::none();
  light.exposure = 0;
  EXPECT_FALSE(light.validate());
  StudioOptions so;
  so.projector_light = light;
  EXPECT_FALSE(so.validate());
}

// (d) The arm swing: the right fingertip's speed (finite differences of the hand ellipsoid's far
// end) peaks at 1.5 m/s; the rest of the body barely moves.
TEST(ArmSwing, FingertipPeaksAtTheConfiguredSpeed) {
  auto tip = [](const ActorBody& b) {
    const Part& h = b.part(PartId::hand_r);
    return Eigen::Vector3d(h.centre + h.axes * Eigen::Vector3d(0, -h.radii.y(), 0));
  };
  for (double peak : {1.5, 1.0}) {
    Actor::Options o = swing_actor();
    o.swing_peak_speed = peak;
    const Actor actor(o);
    double vmax = 0, head_max = 0;
    const double dt = 1e-3;
    for (double t = 0; t < 4; t += 0.005) {
      const ActorBody a = actor.body_at(t), b = actor.body_at(t + dt);
      vmax = std::max(vmax, (tip(b) - tip(a)).norm() / dt);
      head_max = std::max(head_max, (b.head_centre() - a.head_centre()).norm() / dt);
    }
    EXPECT_NEAR(vmax, peak, 0.04 * peak) << peak;
    EXPECT_LT(head_max, 0.1);
  }
  EXPECT_EQ(parse_motion("arm_swing").value(), Motion::arm_swing);
  Actor::Options bad = swing_actor();
  bad.swing_peak_speed = 0;
  EXPECT_FALSE(bad.validate());
}

}  // namespace
}  // namespace studio::sim

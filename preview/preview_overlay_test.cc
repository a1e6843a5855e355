// studio-preview's overlays through the process (issue 16: "head marker; camera and projector
// frusta; what each projector is showing"): this test publishes, over real Cyclone DDS on
// loopback, a head pose (studio/actor/head), a studio camera's calibration, a projector's
// calibration (studio/projector/calibration) and its frames with a four-colour thumbnail
// (studio/projector/frame); `studio-preview --headless --frames 0 --screenshot` draws them.
// Expected pixels are computed here from the viewpoint (scene::perspective x look_at, the
// preview's convention) and the devices' camera models:
//   - the head marker (a yellow sphere) at the head's pixel;
//   - the camera frustum (cyan) at the midpoints of its edges, the image corners' rays cut at
//     0.5 m along the camera's axis;
//   - the projector frustum (magenta) along its centre-to-screen-corner edges;
//   - the screen shows the thumbnail: where the projector's pixel of a screen point falls in a
//     quadrant of its frame, the preview pixel of that point has that quadrant's colour.
// Controls: with every overlay off none of those pixels has an overlay colour; with only the
// screens off (or only the head off) exactly that overlay's pixels go while the others stay.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "core/clock.h"
#include "core/run_mask.h"
#include "preview/viewpoint.h"
#include "scene/view.h"
#include "support/cameras.h"
#include "testing/studio_fixture.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/sample.h"

namespace studio::preview::testing {
namespace {

constexpr int kW = 640, kH = 360;
constexpr int kThumbW = 160, kThumbH = 90;
constexpr const char* kView = "eye=0,1.6,6,at=0,1.2,0,fov=50";

// The thumbnail's quadrants (RGB): top-left red, top-right green, bottom-left blue,
// bottom-right white.
const cv::Vec3b kQuadrant[4] = {{220, 30, 30}, {30, 200, 30}, {30, 30, 220}, {230, 230, 230}};

Camera studio_camera() {
  return support::look_at_camera("cam0", {1.6, 0.9, 2.5}, {0.6, 0.9, -1.0},
                                 Eigen::Vector3d::UnitY(), 352, 288, 400);
}

Projector projector() {
  Projector p;
  p.camera = support::look_at_camera("proj0", {0, 1.5, 4.0}, {0, 1.5, -2}, Eigen::Vector3d::UnitY(),
                                     1280, 720, 1100);
  p.screen = {Eigen::Vector3d(-2, 0.4, -2), Eigen::Vector3d(2, 0.4, -2),
              Eigen::Vector3d(2, 2.6, -2), Eigen::Vector3d(-2, 2.6, -2)};
  return p;
}

// Above the screen, so its sight line to the screen centre crosses no checked screen point.
const Eigen::Vector3d kHead(-0.5, 2.9, 1.5);

enum class Colour { head, camera, projector };
bool is(Colour c, const cv::Vec3b& bgr) {
  const int b = bgr[0], g = bgr[1], r = bgr[2];
  switch (c) {
    case Colour::head:
      return r > 110 && g > 90 && b < 60 && r >= g && 10 * g > 7 * r;  // not orange
    case Colour::camera:
      return r < 90 && g > 140 && b > 140;
    case Colour::projector:
      return r > 140 && g < 90 && b > 140;
  }
  return false;
}

// Any pixel within `radius` of p (pixel coordinates, x right, y down) has the colour.
bool near(const cv::Mat& bgr, const Eigen::Vector2d& p, Colour c, int radius = 2) {
  const int u = int(std::floor(p.x())), v = int(std::floor(p.y()));
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = u + dx, y = v + dy;
      if (x >= 0 && y >= 0 && x < bgr.cols && y < bgr.rows && is(c, bgr.at<cv::Vec3b>(y, x)))
        return true;
    }
  return false;
}

Eigen::Matrix4d clip_from_world() {
  const Viewpoint v = parse_viewpoint(kView).value();
  return scene::perspective(v.fov_deg * std::numbers::pi / 180, double(kW) / kH, 0.05, 200.0) *
         scene::look_at(v.eye, v.at);
}

Eigen::Vector2d pixel(const Eigen::Vector3d& x) {
  bool ok = false;
  const Eigen::Vector2d p = scene::project_to_pixel(clip_from_world(), x, kW, kH, &ok);
  EXPECT_TRUE(ok);
  EXPECT_TRUE(p.x() > 3 && p.y() > 3 && p.x() < kW - 3 && p.y() < kH - 3) << p.transpose();
  return p;
}

// The points each overlay must colour (world frame).
std::vector<Eigen::Vector3d> camera_points() {
  const Camera c = studio_camera();
  const double w = c.width, h = c.height;
  const std::array<Eigen::Vector2d, 4> corners = {
      Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
      Eigen::Vector2d(w - 0.5, h - 0.5), Eigen::Vector2d(-0.5, h - 0.5)};
  std::vector<Eigen::Vector3d> out;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d a = c.unproject(corners[k], 0.5);
    const Eigen::Vector3d b = c.unproject(corners[(k + 1) % 4], 0.5);
    out.push_back(0.5 * (c.centre_in_world() + a));  // apex edge
    out.push_back(0.5 * (a + b));                    // side of the cut
  }
  return out;
}
std::vector<Eigen::Vector3d> projector_points() {
  const Projector p = projector();
  std::vector<Eigen::Vector3d> out;
  for (const auto& corner : p.screen)
    for (double s : {0.35, 0.75})
      out.push_back(p.camera.centre_in_world() + s * (corner - p.camera.centre_in_world()));
  return out;
}
// Screen points where the projector shows each thumbnail quadrant: the ray of projector pixel
// (640 -+ 300, 360 -+ 80) cut with the screen plane z = -2 (inside the screen, clear of the
// quadrants' borders and of the projector frustum's diagonals drawn over the screen).
std::array<Eigen::Vector3d, 4> screen_points() {
  const Projector p = projector();
  std::array<Eigen::Vector3d, 4> out;
  for (int q = 0; q < 4; ++q) {
    const Eigen::Vector2d px(q % 2 == 0 ? 340 : 940, q < 2 ? 280 : 440);
    const Eigen::Vector3d o = p.camera.centre_in_world(), d = p.camera.pixel_ray_in_world(px);
    out[q] = o + ((-2.0 - o.z()) / d.z()) * d;
  }
  return out;
}

class PreviewOverlayTest : public PreviewStudioTest {
 protected:
  // Publishes the calibrations once (transient-local) and the head and projector frames
  // continuously (volatile: a preview that joins later still gets them) until TearDown.
  void publish() {
    participant_ = wire::Participant::create().value();
    cal_topic_ = wire::Topic<studio_CameraCalibration>::create(*participant_).value();
    cal_ = wire::Writer<studio_CameraCalibration>::create(*participant_, *cal_topic_).value();
    wire::Owned<studio_CameraCalibration> c;
    ASSERT_TRUE(wire::from_core(studio_camera(), *c).has_value());
    ASSERT_TRUE(cal_->write(*c).has_value());

    pcal_topic_ = wire::Topic<studio_ProjectorCalibration>::create(*participant_).value();
    pcal_ = wire::Writer<studio_ProjectorCalibration>::create(*participant_, *pcal_topic_).value();
    wire::Owned<studio_ProjectorCalibration> pc;
    ASSERT_TRUE(wire::from_core(projector(), Eigen::Matrix3d::Identity(), *pc).has_value());
    ASSERT_TRUE(pcal_->write(*pc).has_value());

    publisher_ = std::thread([this] {
      auto p = wire::Participant::create().value();
      auto head_topic = wire::Topic<studio_HeadPose>::create(p).value();
      auto heads = wire::Writer<studio_HeadPose>::create(p, head_topic).value();
      auto frame_topic = wire::Topic<studio_ProjectorFrame>::create(p).value();
      auto frames = wire::Writer<studio_ProjectorFrame>::create(p, frame_topic).value();
      std::vector<uint8_t> thumb(std::size_t(kThumbW) * kThumbH * 3);
      for (int y = 0; y < kThumbH; ++y)
        for (int x = 0; x < kThumbW; ++x) {
          const cv::Vec3b& q = kQuadrant[(y >= kThumbH / 2 ? 2 : 0) + (x >= kThumbW / 2 ? 1 : 0)];
          for (int k = 0; k < 3; ++k) thumb[(std::size_t(y) * kThumbW + x) * 3 + k] = q[k];
        }
      for (uint64_t n = 1; !stop_; ++n) {
        wire::Owned<studio_HeadPose> h;
        wire::set(h->actor_id, "actor0");
        h->frame = n;
        h->capture_ns = realtime_ns();
        for (int i = 0; i < 3; ++i) h->position[i] = kHead[i];
        h->velocity[0] = 0.6;  // the velocity line runs +x from the head
        h->confidence = 1;
        (void)heads.write(*h);
        if (n % 4 == 0) {
          wire::Owned<studio_ProjectorFrame> f;
          wire::set(f->projector_id, "proj0");
          f->render_frame = n / 4;
          f->render_done_ns = realtime_ns();
          wire::from_core(RunMask(1280, 720), *f);
          f->thumb_width = kThumbW;
          f->thumb_height = kThumbH;
          wire::assign(f->thumbnail, thumb);
          (void)frames.write(*f);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }

  void TearDown() override {
    stop_ = true;
    if (publisher_.joinable()) publisher_.join();
    PreviewStudioTest::TearDown();
  }

  // One headless screenshot with the given overlays; checks that every overlay's topic arrived.
  cv::Mat shoot(const std::string& name, const std::string& overlays) {
    const auto png = dir_ / (name + ".png");
    Process& p = spawn(name, "preview/studio-preview",
                       {"--headless", "--config", preview_config(name), "--size", "640x360",
                        "--viewpoint", kView, "--frames", "0", "--settle", "4", "--overlays",
                        overlays, "--json", "--screenshot", png.string()});
    const auto code = p.wait_exit(std::chrono::seconds(90));
    EXPECT_EQ(code, 0) << p.log();
    const std::string log = p.log();
    EXPECT_NE(log.find(R"("overlays":{"heads":1,"cameras":1,"projectors":1,"thumbnails":1})"),
              std::string::npos)
        << log;
    return cv::imread(png.string());
  }

  std::optional<wire::Participant> participant_;
  std::optional<wire::Topic<studio_CameraCalibration>> cal_topic_;
  std::optional<wire::Topic<studio_ProjectorCalibration>> pcal_topic_;
  std::optional<wire::Writer<studio_CameraCalibration>> cal_;
  std::optional<wire::Writer<studio_ProjectorCalibration>> pcal_;
  std::thread publisher_;
  std::atomic<bool> stop_{false};
};

struct Seen {
  int head = 0, camera = 0, projector = 0, screen = 0;
};

// What a screenshot shows at the expected places.
Seen look(const cv::Mat& bgr) {
  Seen s;
  s.head = near(bgr, pixel(kHead), Colour::head, 1) ? 1 : 0;
  for (const auto& x : camera_points()) s.camera += near(bgr, pixel(x), Colour::camera) ? 1 : 0;
  for (const auto& x : projector_points())
    s.projector += near(bgr, pixel(x), Colour::projector) ? 1 : 0;
  const auto screen = screen_points();
  for (int q = 0; q < 4; ++q) {
    const Eigen::Vector2d p = pixel(screen[q]);
    int match = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const cv::Vec3b bgr_px = bgr.at<cv::Vec3b>(int(p.y()) + dy, int(p.x()) + dx);
        const cv::Vec3b& want = kQuadrant[q];  // RGB
        bool ok = true;
        for (int k = 0; k < 3; ++k) ok = ok && std::abs(int(bgr_px[2 - k]) - int(want[k])) <= 20;
        match += ok ? 1 : 0;
      }
    s.screen += match == 9 ? 1 : 0;
  }
  return s;
}

TEST_F(PreviewOverlayTest, HeadFrustaAndProjectorScreenAppearWhereTheirGeometryProjects) {
  publish();
  if (HasFatalFailure()) return;

  const cv::Mat all = shoot("all", "all");
  ASSERT_FALSE(all.empty());
  const Seen a = look(all);
  EXPECT_EQ(a.head, 1) << "head marker at " << pixel(kHead).transpose();
  EXPECT_EQ(a.camera, 8) << "camera frustum: points of its 8 edges";
  EXPECT_EQ(a.projector, 8) << "projector frustum: 2 points on each of its 4 edges";
  EXPECT_EQ(a.screen, 4) << "screen: the thumbnail's 4 quadrants where the projector puts them";

  // Control: every overlay off; none of those pixels keeps an overlay colour.
  const Seen none = look(shoot("none", "none"));
  EXPECT_EQ(none.head, 0);
  EXPECT_EQ(none.camera, 0);
  EXPECT_EQ(none.projector, 0);
  EXPECT_EQ(none.screen, 0);

  // One switch at a time: the screens off removes only the thumbnail's colours; the head off
  // only the marker.
  const Seen no_screens = look(shoot("no_screens", "head,cameras,projectors"));
  EXPECT_EQ(no_screens.screen, 0);
  EXPECT_EQ(no_screens.head, 1);
  EXPECT_EQ(no_screens.camera, 8);
  EXPECT_EQ(no_screens.projector, 8);
  const Seen no_head = look(shoot("no_head", "cameras,projectors,screens"));
  EXPECT_EQ(no_head.head, 0);
  EXPECT_EQ(no_head.camera, 8);
  EXPECT_EQ(no_head.screen, 4);
}

// Bad --overlays words: one clear line and exit 2; the positive control above runs good lists.
TEST_F(PreviewOverlayTest, RefusesAnUnknownOverlay) {
  Process& p = spawn("bad", "preview/studio-preview",
                     {"--overlays", "head,frusta", "--headless", "--screenshot", "a.png"});
  const auto code = p.wait_exit(std::chrono::seconds(20));
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 2) << p.log();
  const std::string log = p.log();
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  EXPECT_NE(log.find("'frusta'"), std::string::npos) << log;
  Process& good = spawn("good", "preview/studio-preview",
                        {"--overlays", "head,cameras", "--headless", "--size", "64x48", "--frames",
                         "0", "--settle", "0.2", "--screenshot", (dir_ / "g.png").string()});
  EXPECT_EQ(good.wait_exit(std::chrono::seconds(60)), 0) << good.log();
}

}  // namespace
}  // namespace studio::preview::testing

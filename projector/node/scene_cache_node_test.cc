// The projector's scene cache in the service (issue 15), as a process on loopback fed over DDS:
// the demo museum's nodes, a still head, and a probe node (the museum's flyer, red, high
// contrast, behind the screen) that this test moves left and right. While the eye is still and
// only the probe moves: frames come from the cache (frames_from_cache grows, scene_rerendered
// does not) and every frame shows the probe where it was last put (its red in the thumbnail's
// left or right half). Moving the eye 5 cm (far beyond the bound, about a millimetre) re-renders
// the static scene. Control: with scene_cache.enabled false nothing comes from the cache.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>

#include "core/clock.h"
#include "harness/fixture.h"
#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"
#include "testing/projectors.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/sample.h"
#include "wire/scene_convert.h"
#include "yaml_io/rig_yaml.h"

namespace studio::projector {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

double counter(const studio_ServiceStatus& s, const std::string& name) {
  for (const auto& c : wire::view(s.counters))
    if (name == c.name) return c.value;
  return -1;
}

// Mean column (0..1) of the pure-red pixels of an RGB8 thumbnail; nullopt without any.
std::optional<double> red_column(const studio_ProjectorFrame& f) {
  const auto px = wire::view(f.thumbnail);
  double sum = 0;
  int n = 0;
  for (uint32_t y = 0; y < f.thumb_height; ++y)
    for (uint32_t x = 0; x < f.thumb_width; ++x) {
      const uint8_t* p = &px[(y * f.thumb_width + x) * 3];
      if (p[0] > 150 && p[1] < 40 && p[2] < 40) {
        sum += x;
        ++n;
      }
    }
  if (n < 3) return std::nullopt;
  return sum / n / f.thumb_width;
}

// The test's side of the wire: the projector's status and frames in, scene nodes and the
// followed head out.
struct Wires {
  wire::Participant p = wire::Participant::create().value();
  wire::Topic<studio_ServiceStatus> status_topic =
      wire::Topic<studio_ServiceStatus>::create(p).value();
  wire::Reader<studio_ServiceStatus> status =
      wire::Reader<studio_ServiceStatus>::create(p, status_topic).value();
  wire::Topic<studio_ProjectorFrame> frame_topic =
      wire::Topic<studio_ProjectorFrame>::create(p).value();
  wire::Reader<studio_ProjectorFrame> frames =
      wire::Reader<studio_ProjectorFrame>::create(p, frame_topic).value();
  wire::Topic<studio_SceneNode> node_topic = wire::Topic<studio_SceneNode>::create(p).value();
  wire::Writer<studio_SceneNode> nodes = wire::Writer<studio_SceneNode>::create(p, node_topic).value();
  wire::Topic<studio_HeadPose> head_topic = wire::Topic<studio_HeadPose>::create(p).value();
  wire::Writer<studio_HeadPose> heads = wire::Writer<studio_HeadPose>::create(p, head_topic).value();

  bool node(const scene::Node& n) {
    wire::Owned<studio_SceneNode> s;
    return wire::from_core(n, *s).has_value() && nodes.write(*s).has_value();
  }
  bool head(const Eigen::Vector3d& eye) {
    wire::Owned<studio_HeadPose> h;
    wire::set(h->actor_id, "actor");
    h->capture_ns = realtime_ns();
    for (int i = 0; i < 3; ++i) h->position[i] = eye[i];
    h->confidence = 1;
    return heads.write(*h).has_value();
  }
};

class SceneCacheNodeTest : public studio::testing::ProcessTest {
 protected:
  struct Counts {
    double from_cache = -1, rerendered = -1;
  };

  void SetUp() override {
    ProcessTest::SetUp();
    Rig rig;
    rig.projectors.push_back(testing::half_back_projector());
    ASSERT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()).has_value());
    auto description =
        scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml")
            .value();
    scene_assets::AssetCache cache;
    scene_ = scene_assets::build_scene(description, cache, 0).value();
  }

  std::string config(bool enabled, int hold_frames = 0) {
    const auto path =
        dir_ / ((enabled ? "on" : "off") + std::to_string(hold_frames) + ".yaml");
    std::ofstream(path) << "instance: proj-test\nstatus_period: 0.2\nprojector:\n"
                        << "  rig: rig.yaml\n  id: proj0\n  rate: 20\n"
                        << "  default_eye: [0, 1.6, 1.5]\n"
                        << "  scene_cache: {enabled: " << (enabled ? "true" : "false")
                        << ", max_error_px: 0.5, settle: 1.0, hold_frames: " << hold_frames
                        << "}\n";
    return path.string();
  }

  struct Walk {
    double held = -1, rerendered = -1, from_cache = -1, held_shift_px = -1;
  };
  // Runs a projector while the head walks 5 mm every 50 ms (5-10x the bound per frame) for 3 s;
  // returns the counters' growth over the last 2 s and the last held frame's bound.
  Walk walk(int hold_frames) {
    auto& node = spawn("projector", "projector/studio-projector",
                       {"--config", config(true, hold_frames)});
    EXPECT_TRUE(node.wait_ready(30s)) << node.log();
    Wires w;
    auto& status = w.status;
    EXPECT_TRUE(w.nodes.wait_for_readers(1, 10s));
    for (const auto& [id, n] : scene_.nodes()) EXPECT_TRUE(w.node(n));
    auto latest = [&] {
      Walk got;
      for (auto until = SteadyClock::now() + 5s; got.held < 0 && SteadyClock::now() < until;) {
        for (auto& s : status.take())
          if (s.meta.valid_data && std::string(s.data->service) == "projector")
            got = {counter(*s.data, "frames_held"), counter(*s.data, "scene_rerendered"),
                   counter(*s.data, "frames_from_cache"), counter(*s.data, "scene_held_shift_px")};
        std::this_thread::sleep_for(20ms);
      }
      return got;
    };
    Walk start;
    for (int k = 0; k < 60; ++k) {
      if (k == 20) {
        (void)status.take();
        start = latest();
      }
      EXPECT_TRUE(w.head(Eigen::Vector3d(-0.3 + 0.005 * k, 1.65, 1.2)));
      std::this_thread::sleep_for(50ms);
    }
    (void)status.take();
    const Walk end = latest();
    EXPECT_TRUE(node.running());
    EXPECT_EQ(node.stop(), 0) << node.log();
    return {end.held - start.held, end.rerendered - start.rerendered,
            end.from_cache - start.from_cache, end.held_shift_px};
  }

  // Runs a projector; returns the counts while only the probe moved and after the eye moved.
  void run(bool enabled, Counts& still_start, Counts& still_end, Counts& moved, int& shown_right) {
    auto& node = spawn("projector", "projector/studio-projector", {"--config", config(enabled)});
    ASSERT_TRUE(node.wait_ready(30s)) << node.log();
    Wires w;
    auto& frames = w.frames;
    auto& status = w.status;
    ASSERT_TRUE(w.nodes.wait_for_readers(1, 10s));
    const scene::Node* flyer = nullptr;
    for (const auto& [id, n] : scene_.nodes()) {
      ASSERT_TRUE(w.node(n));
      if (id.ends_with("flyer")) flyer = &n;
    }
    ASSERT_TRUE(flyer);
    Eigen::Vector3d eye(0.1, 1.65, 1.2);
    auto publish = [&](double probe_x) {
      ASSERT_TRUE(w.head(eye));
      scene::Node probe = *flyer;  // wings facing the eye, 1 m behind the screen
      probe.id = "probe";
      probe.parent = "";
      probe.local.translation = Eigen::Vector3d(probe_x, 1.2, -3.0);
      probe.local.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX());
      probe.material.colour = {1, 0, 0, 1};
      probe.material.high_contrast = true;
      ASSERT_TRUE(w.node(probe));
    };
    auto counts = [&] {
      Counts c;
      for (auto until = SteadyClock::now() + 5s; c.from_cache < 0 && SteadyClock::now() < until;) {
        for (auto& s : status.take())
          if (s.meta.valid_data && std::string(s.data->service) == "projector")
            c = {counter(*s.data, "frames_from_cache"), counter(*s.data, "scene_rerendered")};
        std::this_thread::sleep_for(50ms);
      }
      return c;
    };
    // The probe moves every 100 ms for 1.5 s: it is moving (changed within `settle`).
    for (int k = 0; k < 15; ++k) {
      publish(k % 2 ? 1.0 : -1.0);
      std::this_thread::sleep_for(100ms);
    }
    (void)status.take();
    still_start = counts();
    shown_right = 0;
    for (int k = 0; k < 8; ++k) {
      const double x = k % 2 ? 1.0 : -1.0;
      publish(x);
      std::this_thread::sleep_for(150ms);
      publish(x);  // keeps the head fresh; the same probe state: no change
      std::this_thread::sleep_for(150ms);
      std::optional<double> column;
      for (auto& s : frames.take())
        if (s.meta.valid_data) column = red_column(*s.data);  // the newest frame's
      ASSERT_TRUE(column) << "probe not in the frame, step " << k << "\n" << node.log();
      shown_right += (*column > 0.5) == (x > 0);
    }
    (void)status.take();
    still_end = counts();
    eye += Eigen::Vector3d(0.05, 0, 0);  // far beyond the bound
    for (int k = 0; k < 6; ++k) {
      publish(1.0);
      std::this_thread::sleep_for(100ms);
    }
    (void)status.take();
    moved = counts();
    EXPECT_TRUE(node.running());
    EXPECT_EQ(node.stop(), 0) << node.log();
  }

  scene::Scene scene_;
};

TEST_F(SceneCacheNodeTest, StillEyeRendersFromTheCacheWhileTheMovingNodeMovesEveryFrame) {
  Counts a, b, c;
  int right = 0;
  run(true, a, b, c, right);
  std::printf("cache on: from cache %.0f -> %.0f, re-rendered %.0f -> %.0f; eye moved: "
              "re-rendered %.0f; probe where it was put in %d of 8 frames\n",
              a.from_cache, b.from_cache, a.rerendered, b.rerendered, c.rerendered, right);
  EXPECT_EQ(right, 8);
  EXPECT_GE(b.from_cache - a.from_cache, 20);  // ~2.4 s at 20 fps
  EXPECT_LE(b.rerendered - a.rerendered, 1);   // (a frame of the eye's first position at most)
  EXPECT_GE(c.rerendered - b.rerendered, 1);   // the eye moved beyond the bound
}

TEST_F(SceneCacheNodeTest, CacheOffRendersEveryFrame) {
  Counts a, b, c;
  int right = 0;
  run(false, a, b, c, right);
  std::printf("cache off: from cache %.0f -> %.0f, re-rendered %.0f -> %.0f\n", a.from_cache,
              b.from_cache, a.rerendered, b.rerendered);
  EXPECT_EQ(right, 8);
  EXPECT_EQ(b.from_cache, 0);
  EXPECT_GE(b.rerendered - a.rerendered, 20);
}

}  // namespace
}  // namespace studio::projector

namespace studio::projector {
namespace {

// scene_cache.hold_frames 2 with a walking head: about two frames in three restore the layer
// beyond the bound (frames_held, counted as from the cache) and one in three draws the scene;
// the held frames' bound is reported (scene_held_shift_px, beyond max_error_px). Control:
// hold_frames 0 draws every frame of the walk.
TEST_F(SceneCacheNodeTest, HoldFramesServeAWalkingHeadBetweenRedraws) {
  const Walk on = walk(2);
  const Walk off = walk(0);
  std::printf("walking head, 2 s: hold 2: held %.0f, re-rendered %.0f, from the cache %.0f, last "
              "held bound %.2f px; hold 0: held %.0f, re-rendered %.0f, from the cache %.0f\n",
              on.held, on.rerendered, on.from_cache, on.held_shift_px, off.held, off.rerendered,
              off.from_cache);
  EXPECT_GE(on.held + on.rerendered, 20);  // ~40 frames at 20 fps
  EXPECT_GE(on.held, on.rerendered);
  EXPECT_LE(on.held, 2 * on.rerendered + 2);  // a layer serves at most 2 frames
  EXPECT_GE(on.from_cache, on.held);          // (+ frames before the next head pose)
  EXPECT_GT(on.held_shift_px, 0.5);
  EXPECT_EQ(off.held, 0);
  EXPECT_GE(off.rerendered, 20);
}

}  // namespace
}  // namespace studio::projector

// The projector service as a real process on loopback, fed by this test over DDS: the scene's
// nodes (the demo museum, published as the scene server publishes them), an actor mesh and the
// actor's head. Observed over DDS: its calibration (from the rig), its frames (blackout mask at
// full resolution, thumbnail, latency, margin) and its status. The blackout mask is checked
// against the projector camera's own projection of the grown mesh (computed here, independently
// of the renderer); bad input (an eye behind the screen, an empty mesh) is counted and the
// projection goes on; a degenerate screen is one line at start.
#include <gtest/gtest.h>

#include <algorithm>

#include <fstream>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include "core/clock.h"
#include "harness/fixture.h"
#include "projector/mask_geometry.h"
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

// A closed box (12 triangles, outward faces) centred at c with half size h.
ActorMesh box(const Eigen::Vector3f& c, float h, int64_t capture_ns) {
  ActorMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back(c + h * Eigen::Vector3f(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  m.capture_ns = capture_ns;
  return m;
}

void to_wire(const ActorMesh& m, const std::string& id, uint64_t frame, studio_ActorMesh& s) {
  wire::set(s.actor_id, id);
  s.frame = frame;
  s.capture_ns = m.capture_ns;
  s.source_frame = frame;
  std::vector<float> v;
  std::vector<uint32_t> t;
  for (const auto& p : m.vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
  for (const auto& tri : m.triangles) t.insert(t.end(), tri.begin(), tri.end());
  wire::assign(s.vertices, v);
  wire::assign(s.triangles, t);
}

// The projector pixels of the mesh's silhouette: every triangle projected by the projector's
// camera model (core Camera::project) and filled, 255 inside.
cv::Mat expected_mask(const Camera& cam, const ActorMesh& m) {
  cv::Mat out(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  for (const auto& t : m.triangles) {
    std::vector<cv::Point> pts;
    for (uint32_t k : t) {
      Eigen::Vector2d px;
      if (!cam.project(m.vertices[k].cast<double>(), &px)) return {};
      pts.emplace_back(int(std::lround(px.x() * 16)), int(std::lround(px.y() * 16)));
    }
    cv::fillConvexPoly(out, pts, cv::Scalar(255), cv::LINE_8, 4);
  }
  return out;
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  const double i = cv::countNonZero(a & b), u = cv::countNonZero(a | b);
  return u > 0 ? i / u : 0;
}

double counter(const studio_ServiceStatus& s, const std::string& name) {
  for (const auto& c : wire::view(s.counters))
    if (name == c.name) return c.value;
  return -1;
}

// This test's end of the wire: the projector's outputs read, its inputs written.
struct Wires {
  wire::Participant p = wire::Participant::create().value();
  wire::Reader<studio_ProjectorCalibration> cal = reader<studio_ProjectorCalibration>();
  wire::Reader<studio_ProjectorFrame> frames = reader<studio_ProjectorFrame>();
  wire::Reader<studio_ServiceStatus> status = reader<studio_ServiceStatus>();
  wire::Writer<studio_SceneNode> nodes = writer<studio_SceneNode>();
  wire::Writer<studio_ActorMesh> meshes = writer<studio_ActorMesh>();
  wire::Writer<studio_HeadPose> heads = writer<studio_HeadPose>();

  template <class T>
  wire::Reader<T> reader() {
    return wire::Reader<T>::create(p, wire::Topic<T>::create(p).value()).value();
  }
  template <class T>
  wire::Writer<T> writer() {
    return wire::Writer<T>::create(p, wire::Topic<T>::create(p).value()).value();
  }
  // Every node of `scene`, as the scene server publishes them.
  void publish_scene(const scene::Scene& scene) {
    ASSERT_TRUE(nodes.wait_for_readers(1, 10s));
    for (const auto& [id, n] : scene.nodes()) {
      wire::Owned<studio_SceneNode> s;
      ASSERT_TRUE(wire::from_core(n, *s).has_value());
      ASSERT_TRUE(nodes.write(*s).has_value());
    }
  }
  // The followed actor's head at `at`, captured now.
  void publish_head(const Eigen::Vector3d& at) {
    wire::Owned<studio_HeadPose> h;
    wire::set(h->actor_id, "actor");
    h->capture_ns = realtime_ns();
    for (int i = 0; i < 3; ++i) h->position[i] = at[i];
    h->confidence = 1;
    ASSERT_TRUE(heads.write(*h).has_value());
  }
};

class ProjectorNodeTest : public studio::testing::ProcessTest {
 protected:
  std::string write_files(const Projector& p, const std::string& extra = "") {
    Rig rig;
    rig.projectors.push_back(p);
    EXPECT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()).has_value());
    const auto path = dir_ / "projector.yaml";
    std::ofstream(path) << "instance: proj-test\nstatus_period: 0.2\nprojector:\n"
                        << "  rig: rig.yaml\n  id: proj0\n  rate: 10\n"
                        << "  default_eye: [0, 1.6, 1.5]\n"
                        << extra;
    return path.string();
  }
};

TEST_F(ProjectorNodeTest, RendersTheSceneMasksTheActorAndReportsOverDds) {
  const Projector projector = testing::half_back_projector();
  auto& node =
      spawn("projector", "projector/studio-projector", {"--config", write_files(projector)});
  ASSERT_TRUE(node.wait_ready(30s)) << node.log();

  Wires w;
  auto& cal = w.cal;
  auto& frames = w.frames;
  auto& status = w.status;
  auto& meshes = w.meshes;

  // The calibration, from the rig file (transient-local: arrives although written before).
  std::optional<Projector> published;
  for (auto until = SteadyClock::now() + 10s; !published && SteadyClock::now() < until;) {
    for (auto& s : cal.take())
      if (s.meta.valid_data) published = wire::to_core(*s.data).value();
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(published) << node.log();
  EXPECT_EQ(published->camera.width, 960);
  EXPECT_NEAR(published->camera.intrinsics.fx, projector.camera.intrinsics.fx, 1e-9);
  EXPECT_LT((published->camera.centre_in_world() - projector.camera.centre_in_world()).norm(),
            1e-9);
  for (int k = 0; k < 4; ++k) EXPECT_LT((published->screen[k] - projector.screen[k]).norm(), 1e-12);

  // The scene, as the scene server publishes it: every node of the demo scene.
  auto description =
      scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml").value();
  scene_assets::AssetCache cache;
  auto scene = scene_assets::build_scene(description, cache, 0).value();
  w.publish_scene(scene);

  // The actor: a 0.5 m box in front of the back wall, and its head.
  ASSERT_TRUE(meshes.wait_for_readers(1, 10s));
  const int64_t capture_ns = realtime_ns() - 20'000'000;
  const ActorMesh actor = box({0.2f, 1.0f, -0.5f}, 0.25f, capture_ns);
  wire::Owned<studio_ActorMesh> m;
  to_wire(actor, "actor0", 1234, *m);
  ASSERT_TRUE(meshes.write(*m).has_value());
  auto publish_head = [&](const Eigen::Vector3d& at) { w.publish_head(at); };
  const Eigen::Vector3d eye(0.1, 1.65, 1.2);

  // A frame with the mesh: stamped with its frame and capture time, the mask where the
  // projector's camera model puts the mesh grown by the margin the frame reports.
  std::optional<wire::Owned<studio_ProjectorFrame>> got;
  for (auto until = SteadyClock::now() + 25s; !got && SteadyClock::now() < until;) {
    publish_head(eye);
    for (auto& s : frames.take())
      if (s.meta.valid_data && s.data->actors == 1 && s.data->eye[2] == eye.z())
        got = std::move(s.data);
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(got) << node.log();
  const studio_ProjectorFrame& f = **got;
  EXPECT_EQ(std::string(f.projector_id), "proj0");
  EXPECT_EQ(f.frame, 1234u);
  EXPECT_EQ(f.capture_ns, capture_ns);
  EXPECT_GT(f.render_done_ns, capture_ns);
  EXPECT_NEAR(f.latency_ms, (f.render_done_ns - capture_ns) * 1e-6, 1e-3);
  EXPECT_FALSE(f.two_pass);
  EXPECT_GE(f.margin_m, 0.01 - 1e-9);  // the configured floor at least
  // The actor's first mesh has no motion estimate: its margin covers its age at the worst-case
  // acceleration (an actor at rest at the capture may be moving by the display), up to the cap.
  // (Its age at the display: the frame's latency + the default 16 ms display lag, as planned.)
  const double age = f.latency_ms * 1e-3 + 0.016;
  EXPECT_NEAR(f.margin_m, std::min(0.2, 0.01 + 0.5 * 15 * age * age), 0.015);
  auto blackout = wire::to_core(f).value();
  ASSERT_EQ(blackout.width(), 960);
  const Mask bm = blackout.to_mask();
  const cv::Mat got_mask(bm.height(), bm.width(), CV_8UC1, const_cast<uint8_t*>(bm.data()));
  // The node's default mask_growth: outline (mask_geometry.h grow_outline; its own tests check
  // it against ray casting).
  GrowOptions outline;
  outline.projector = projector.camera;
  const cv::Mat want =
      expected_mask(projector.camera, grow_mask(MaskBase{actor, 0, {}}, f.margin_m, outline).value());
  ASSERT_FALSE(want.empty());
  const double mask_iou = iou(got_mask, want);
  std::printf("frame %llu: latency %.1f ms, margin %.1f mm, blackout %d px, IoU %.4f\n",
              static_cast<unsigned long long>(f.render_frame), f.latency_ms, f.margin_m * 1e3,
              cv::countNonZero(got_mask), mask_iou);
  EXPECT_GT(mask_iou, 0.97) << cv::countNonZero(got_mask) << " vs " << cv::countNonZero(want);
  // The thumbnail shows the scene (the museum is lit: far from a black frame).
  ASSERT_EQ(f.thumb_width * f.thumb_height * 3, wire::view(f.thumbnail).size());
  double sum = 0;
  for (uint8_t b : wire::view(f.thumbnail)) sum += b;
  EXPECT_GT(sum / wire::view(f.thumbnail).size(), 10.0);

  // Bad input: an eye behind the screen and an empty mesh are counted; the projection goes on
  // from the last good eye, with the last good mask.
  publish_head({0, 1.6, -4});
  wire::Owned<studio_ActorMesh> empty;
  wire::set(empty->actor_id, "actor0");
  empty->capture_ns = realtime_ns();
  ASSERT_TRUE(meshes.write(*empty).has_value());
  bool counted = false;
  uint64_t last_render = f.render_frame;
  int later_frames = 0;
  for (auto until = SteadyClock::now() + 15s;
       !(counted && later_frames >= 3) && SteadyClock::now() < until;) {
    publish_head({0, 1.6, -4});
    for (auto& s : status.take())
      if (s.meta.valid_data && std::string(s.data->service) == "projector")
        counted = counter(*s.data, "eye_rejected") > 0 &&
                  counter(*s.data, "meshes_rejected_empty") >= 1 &&
                  counter(*s.data, "margin_mm") >= 10 - 1e-6 &&  // gauges: the margin in use
                  counter(*s.data, "latency_p_ms") > 0;          // and the latency it covers
    for (auto& s : frames.take())
      if (s.meta.valid_data && s.data->render_frame > last_render) {
        last_render = s.data->render_frame;
        ++later_frames;
        EXPECT_EQ(s.data->eye[2], eye.z());  // the last good eye
        EXPECT_EQ(s.data->actors, 1u);       // the last good mesh
      }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(counted) << node.log();
  EXPECT_GE(later_frames, 3);

  // A burst of meshes faster than frames are drawn (a hull catching up): the newest is drawn and
  // the older ones are not queued (dropped by the reader's keep-last history or, once taken,
  // by the node's MeshInbox: meshes_superseded; its logic is MeshInbox's unit test).
  const int64_t base = std::max(capture_ns + 1'000'000, realtime_ns() - 1'200'000'000);
  for (int k = 1; k <= 30; ++k) {
    wire::Owned<studio_ActorMesh> b;
    to_wire(box({0.2f, 1.0f, -0.5f}, 0.25f, base + k * 40'000'000), "actor0", 2000 + k, *b);
    ASSERT_TRUE(meshes.write(*b).has_value());
  }
  bool newest = false;
  std::set<uint64_t> drawn;
  for (auto until = SteadyClock::now() + 15s; !newest && SteadyClock::now() < until;) {
    for (auto& s : frames.take())
      if (s.meta.valid_data && s.data->frame > 2000) {
        drawn.insert(s.data->frame);
        newest = newest || s.data->frame == 2030;
      }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(newest) << node.log();
  EXPECT_LT(drawn.size(), 30u);  // not one frame per mesh of the burst
  // The burst's meshes were fitted on the fit thread (the default, fit_thread: true) and the fits
  // installed: the status times them; the ones a newer mesh overtook are counted.
  bool fitted = false;
  for (auto until = SteadyClock::now() + 10s; !fitted && SteadyClock::now() < until;) {
    for (auto& s : status.take())
      if (s.meta.valid_data && std::string(s.data->service) == "projector")
        fitted = counter(*s.data, "stage_motion_ms") > 0 &&
                 counter(*s.data, "motion_fits_deferred") >= 0;
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(fitted) << node.log();

  // The actor leaves (the hull disposes its mesh): no mask any more.
  ASSERT_TRUE(meshes.dispose(*m).has_value());
  bool cleared = false;
  for (auto until = SteadyClock::now() + 10s; !cleared && SteadyClock::now() < until;) {
    for (auto& s : frames.take())
      if (s.meta.valid_data && s.data->actors == 0)
        cleared = wire::to_core(*s.data).value().area() == 0;
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(cleared);
  EXPECT_TRUE(node.running());
  EXPECT_EQ(node.stop(), 0) << node.log();
}

TEST_F(ProjectorNodeTest, DegenerateScreenIsOneLineAtStart) {
  // The rig as a stage could hand it over: the screen's corners on one line (write_rig refuses
  // to write such a rig, so the text is edited after a good one was written).
  const std::string config = write_files(testing::half_back_projector());
  std::ifstream in(dir_ / "rig.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string rig = text.str();
  const auto at = rig.find("corners:");
  ASSERT_NE(at, std::string::npos) << rig;
  rig = rig.substr(0, at) + "corners: [[-2, 0, -2], [0, 0, -2], [2, 0, -2], [4, 0, -2]]}\n";
  std::ofstream(dir_ / "rig.yaml") << rig;
  auto& node = spawn("projector", "projector/studio-projector", {"--config", config});
  const auto code = node.wait_exit(30s);
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
  EXPECT_NE(node.log().find("screen"), std::string::npos) << node.log();
}

TEST_F(ProjectorNodeTest, EyeBehindTheScreenAsDefaultIsRefusedAtStart) {
  auto& node =
      spawn("projector", "projector/studio-projector",
            {"--config", write_files(testing::half_back_projector(), "  form: two_pass\n")});
  (void)node;
  // A good two-pass config starts (the positive control of the refusal below).
  ASSERT_TRUE(node.wait_ready(30s)) << node.log();
  EXPECT_EQ(node.stop(), 0);
  std::ofstream(dir_ / "bad.yaml") << "projector:\n  rig: rig.yaml\n  id: proj0\n"
                                   << "  default_eye: [0, 1.6, -5]\n";
  auto& bad =
      spawn("bad", "projector/studio-projector", {"--config", (dir_ / "bad.yaml").string()});
  const auto code = bad.wait_exit(30s);
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
  EXPECT_NE(bad.log().find("default_eye"), std::string::npos) << bad.log();
}

}  // namespace
}  // namespace studio::projector

namespace studio::projector {
namespace {

// scene_thread (the default): the scene drawn on a thread of its own, on a display of its own,
// and the frame's masks put over its newest image; the same picture as the scene drawn on the
// render thread (scene_thread: false): the thumbnails of a frame from the same head, with the
// scene alone, are the same; the status says which path drew it.
TEST_F(ProjectorNodeTest, SceneThreadShowsWhatTheRenderThreadDraws) {
  const Projector projector = testing::half_back_projector();
  auto description =
      scene_config::read_scene_file(std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml").value();
  scene_assets::AssetCache cache;
  auto scene = scene_assets::build_scene(description, cache, 0).value();
  const Eigen::Vector3d eye(0.1, 1.65, 1.2);
  std::vector<std::vector<uint8_t>> thumbs;
  for (const bool thread : {false, true}) {
    auto& node = spawn("projector", "projector/studio-projector",
                       {"--config", write_files(projector, thread ? "" : "  scene_thread: false\n")});
    ASSERT_TRUE(node.wait_ready(30s)) << node.log();
    Wires w;
    w.publish_scene(scene);
    // Frames from the head, once the whole scene is in (a later frame than the first such).
    std::optional<wire::Owned<studio_ProjectorFrame>> got;
    int from_eye = 0;
    double images = -1, ahead = -1;
    for (auto until = SteadyClock::now() + 25s; !(got && images >= 0) && SteadyClock::now() < until;) {
      w.publish_head(eye);
      for (auto& s : w.frames.take())
        if (s.meta.valid_data && s.data->eye[2] == eye.z() && ++from_eye == 5)
          got = std::move(s.data);
      for (auto& s : w.status.take())
        if (got && s.meta.valid_data && std::string(s.data->service) == "projector") {
          images = counter(*s.data, "scene_images_drawn");
          ahead = counter(*s.data, "stage_ahead_ms");
        }
      std::this_thread::sleep_for(50ms);
    }
    ASSERT_TRUE(got) << node.log();
    const studio_ProjectorFrame& f = **got;
    EXPECT_EQ(f.actors, 0u);
    ASSERT_EQ(f.thumb_width * f.thumb_height * 3, wire::view(f.thumbnail).size());
    thumbs.emplace_back(wire::view(f.thumbnail).begin(), wire::view(f.thumbnail).end());
    if (thread) {
      EXPECT_GT(images, 0) << node.log();  // images from the scene thread
      EXPECT_EQ(ahead, 0);                 // none drawn ahead on the render thread
    } else {
      EXPECT_EQ(images, 0);
      EXPECT_GT(ahead, 0);
    }
    EXPECT_EQ(node.stop(), 0) << node.log();
  }
  ASSERT_EQ(thumbs.size(), 2u);
  ASSERT_EQ(thumbs[0].size(), thumbs[1].size());
  int differ = 0, most = 0;
  double sum = 0;
  for (std::size_t i = 0; i < thumbs[0].size(); ++i) {
    const int d = std::abs(int(thumbs[0][i]) - int(thumbs[1][i]));
    differ += d > 0;
    most = std::max(most, d);
    sum += thumbs[1][i];
  }
  std::printf("thumbnails, render thread vs scene thread: %d of %zu values differ, by %d at most\n",
              differ, thumbs[0].size(), most);
  EXPECT_EQ(most, 0);
  EXPECT_GT(sum / double(thumbs[1].size()), 10.0);  // the lit museum, not a black frame
}

// The example configs (projector/node/ and the example studio's, deploy/examples/studio/) start
// as they are and publish their projector's calibration.
TEST_F(ProjectorNodeTest, ExampleConfigsStart) {
  for (const std::string& config :
       {std::string(STUDIO_SOURCE_DIR) + "/projector/node/projector.example.yaml",
        std::string(STUDIO_SOURCE_DIR) + "/deploy/examples/studio/projector-proj1.yaml"}) {
    auto& node = spawn("projector", "projector/studio-projector", {"--config", config});
    ASSERT_TRUE(node.wait_ready(30s)) << config << "\n" << node.log();
    auto p = wire::Participant::create().value();
    auto topic = wire::Topic<studio_ProjectorCalibration>::create(p).value();
    auto cal = wire::Reader<studio_ProjectorCalibration>::create(p, topic).value();
    bool got = false;
    for (auto until = SteadyClock::now() + 10s; !got && SteadyClock::now() < until;) {
      for (auto& s : cal.take())
        got = got || (s.meta.valid_data && std::string(s.data->projector_id) == "proj1");
      std::this_thread::sleep_for(20ms);
    }
    EXPECT_TRUE(got) << config;
    EXPECT_EQ(node.stop(), 0) << node.log();
  }
}

}  // namespace
}  // namespace studio::projector

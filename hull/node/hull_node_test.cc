// The hull service as a real process on loopback: simulated-studio masks in over DDS, per-actor
// segments and a watertight mesh out, stamped with the masks' frame and capture time; a missing
// camera is waited for until the deadline and then the frame goes out without it; bad config is
// one line. refine: true (default) publishes the mesh with exact crossings, refine: false the
// half-cell one.
#include "hull_node.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "harness/fixture.h"
#include "hull/crossing_refine.h"
#include "hull/projector_mask.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "support/cameras.h"
#include "wire/actor_convert.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/sample.h"
#include "yaml_io/rig_yaml.h"

namespace studio::hull {
namespace {

using namespace std::chrono_literals;

class HullNodeTest : public testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    sim::RingOptions ring;
    ring.width = 352;
    ring.height = 288;
    ring.focal_px = 280;
    cameras_ = sim::ring_cameras(ring);
    ASSERT_TRUE(support::write_rig_yaml(cameras_, dir_ / "rig.yaml").has_value());
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::walk;
    studio_.emplace(sim::SimulatedStudio::create(cameras_, so).value());
  }

  std::string write_config(const std::string& hull_section) {
    const auto path = dir_ / "hull.yaml";
    std::ofstream(path) << "instance: hull-test\nstatus_period: 0.5\nhull:\n  rig: rig.yaml\n"
                        << hull_section;
    return path.string();
  }

  // Publishes the true masks of `frame` for the cameras in `which`.
  void publish_masks(wire::Writer<studio_AlphaMask>& writer, int64_t frame, int64_t capture_ns,
                     const std::vector<int>& which) {
    for (int c : which) {
      Mask m;
      studio_->render(c, frame, nullptr, &m);
      wire::Owned<studio_AlphaMask> s;
      wire::set(s->camera_id, cameras_[c].id);
      s->frame = uint64_t(frame);
      s->capture_ns = capture_ns;
      wire::from_core(RunMask::from_mask(m.view()), studio_MASK_CODEC, *s);
      ASSERT_TRUE(writer.write(*s).has_value());
    }
  }

  // Every camera's true mask of `frame` as runs, and the views over them (pointing into runs:
  // a moved vector keeps its elements where they are).
  struct TrueMasks {
    std::vector<RunMask> runs;
    std::vector<View> views;
  };
  TrueMasks true_masks(int64_t frame) {
    TrueMasks t;
    t.runs.resize(cameras_.size());
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      Mask truth;
      studio_->render(int(c), frame, nullptr, &truth);
      t.runs[c] = RunMask::from_mask(truth.view());
    }
    for (std::size_t c = 0; c < cameras_.size(); ++c) t.views.push_back({&cameras_[c], &t.runs[c]});
    return t;
  }

  std::vector<int> all_cameras() const {
    std::vector<int> all(cameras_.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = int(i);
    return all;
  }

  // The hull config of the projector-mask tests, and the library's viewpoint-cut mask the node
  // should publish for `projector` and `frame` with every camera's true mask.
  static constexpr const char* kProjectorMaskSection =
      "  box: [-1.5, 0, -1.5, 1.5, 2.2, 1.5]\n  grid: 64\n  deadline_ms: 300\n"
      "  projector_masks: true\n  projector_mask_step: 2\n";
  RunMask library_projector_mask(const Camera& projector, int64_t frame) {
    const TrueMasks truth = true_masks(frame);
    ProjectorMaskOptions po;
    po.step = 2;
    return projector_mask(
               projector,
               Eigen::AlignedBox3d(Eigen::Vector3d(-1.5, 0, -1.5), Eigen::Vector3d(1.5, 2.2, 1.5)),
               truth.views, po)
        .value();
  }

  // The actor0 mesh the node should publish for `frame` with every camera's true mask: segment
  // marching cubes of the largest component, half-cell (plain) and with exact crossings.
  std::pair<Mesh, Mesh> local_meshes(int64_t frame, const HullNodeOptions& o) {
    const TrueMasks truth = true_masks(frame);
    const std::vector<View>& views = truth.views;
    auto local = visual_hull(o.grid_spec(), views);
    EXPECT_TRUE(local.has_value());
    if (!local) return {};
    const auto actors = connected_components(*local, o.min_actor_volume);
    if (actors.empty()) return {};
    std::pair<Mesh, Mesh> out{segment_marching_cubes(actors[0]), Mesh{}};
    out.second = out.first;
    EXPECT_TRUE(refine_crossings(out.second, actors[0], views).has_value());
    return out;
  }

  void masks_in_segments_and_mesh_out(bool refine);

  std::vector<Camera> cameras_;
  std::optional<sim::SimulatedStudio> studio_;
};

// Masks of every camera in; segments and mesh out; `refine` is the config's refine key.
void HullNodeTest::masks_in_segments_and_mesh_out(bool refine) {
  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto seg_topic = wire::Topic<studio_SegmentSet>::create(p).value();
  auto segs = wire::Reader<studio_SegmentSet>::create(p, seg_topic).value();
  auto mesh_topic = wire::Topic<studio_ActorMesh>::create(p).value();
  auto meshes = wire::Reader<studio_ActorMesh>::create(p, mesh_topic).value();

  auto& hull = spawn(
      "hull", "hull/studio-hull",
      {"--config",
       write_config("  box: [-1.5, 0, -1.5, 1.5, 2.2, 1.5]\n  grid: 96\n  deadline_ms: 200\n" +
                    std::string(refine ? "" : "  refine: false\n  mesh_normals: true\n"))});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));

  HullNodeOptions options;
  options.box = {-1.5, 0, -1.5, 1.5, 2.2, 1.5};
  options.grid = 96;
  const std::vector<int> all = all_cameras();
  const int64_t frame = 40, capture_ns = 1'700'000'000'000'000'000;
  std::optional<hull::SegmentSet> set;
  std::optional<wire::Owned<studio_ActorMesh>> mesh;
  // Best-effort masks: resend the frame until the node answers (the first may precede matching).
  for (int attempt = 0; attempt < 20 && !(set && mesh); ++attempt) {
    publish_masks(masks, frame + attempt, capture_ns + attempt, all);
    const auto until = std::chrono::steady_clock::now() + 1s;
    while (std::chrono::steady_clock::now() < until && !(set && mesh)) {
      for (auto& s : segs.take())
        if (s.meta.valid_data && std::string(s.data->actor_id) == "actor0") {
          EXPECT_EQ(s.data->capture_ns - capture_ns, int64_t(s.data->frame) - frame);
          auto core = wire::to_core(*s.data);
          ASSERT_TRUE(core.has_value()) << core.error().message;
          set = std::move(*core);
        }
      // Only a mesh made from every camera's mask (a best-effort mask may be lost, and a frame
      // then goes out without it at the deadline): its vertex count is that of the local mesh.
      for (auto& m : meshes.take())
        if (m.meta.valid_data &&
            wire::view(m.data->vertices).size() ==
                3 * local_meshes(int64_t(m.data->frame), options).second.vertices.size())
          mesh = std::move(m.data);
      std::this_thread::sleep_for(20ms);
    }
  }
  ASSERT_TRUE(set.has_value()) << hull.log();
  ASSERT_TRUE(mesh.has_value()) << hull.log();

  // The hull holds the actor: the true head centre and most true surface points are inside.
  const auto truth = studio_->truth(int64_t((*mesh)->frame));
  EXPECT_TRUE(set->contains(truth.head_centre()));
  EXPECT_GT(set->volume(), 0.02);
  EXPECT_LT(set->volume(), 0.6);
  // The mesh arrives whole: watertight and consistently oriented.
  hull::Mesh m;
  auto v = wire::view((*mesh)->vertices);
  auto t = wire::view((*mesh)->triangles);
  ASSERT_GT(t.size(), 300u);
  for (std::size_t i = 0; i + 2 < v.size(); i += 3)
    m.vertices.emplace_back(v[i], v[i + 1], v[i + 2]);
  for (std::size_t i = 0; i + 2 < t.size(); i += 3)
    m.triangles.push_back({t[i], t[i + 1], t[i + 2]});
  const auto topo = hull::check_topology(m);
  EXPECT_TRUE(topo.watertight());
  EXPECT_TRUE(topo.oriented());
  EXPECT_EQ((*mesh)->source_frame, (*mesh)->frame);
  // Normals only with mesh_normals (the refine: false run sets it): one unit vector per vertex.
  const auto normals = wire::view((*mesh)->normals);
  if (refine) {
    EXPECT_TRUE(normals.empty());
  } else {
    ASSERT_EQ(normals.size(), v.size());
    for (std::size_t i = 0; i + 2 < normals.size(); i += 3)
      ASSERT_NEAR(Eigen::Vector3f(normals[i], normals[i + 1], normals[i + 2]).norm(), 1.0f, 1e-3f);
  }

  // refine: true (the default): the published mesh is the actor's segment marching cubes mesh
  // with exact crossings; refine: false: the half-cell one.
  const auto [plain, exact] = local_meshes(int64_t((*mesh)->frame), options);
  ASSERT_EQ(m.vertices.size(), exact.vertices.size());
  float off_exact = 0, off_plain = 0;
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    off_exact = std::max(off_exact, (m.vertices[k] - exact.vertices[k]).norm());
    off_plain = std::max(off_plain, (m.vertices[k] - plain.vertices[k]).norm());
  }
  const float cell = float(options.grid_spec().du());
  EXPECT_LT(refine ? off_exact : off_plain, 1e-5f);
  EXPECT_GT(refine ? off_plain : off_exact, 0.2f * cell);

  // The status says where the frames' time went (hull_stages.h): every stage gauge is there, the
  // work stages took time, the crossings only when refining, and the stages fit in the total.
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(p).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(p, status_topic).value();
  std::map<std::string, double> g;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until && !g.contains("mask_to_mesh_ms")) {
    for (auto& s : status.take())
      if (s.meta.valid_data && std::string(s.data->service) == "hull")
        for (const auto& c : wire::view(s.data->counters)) g[c.name] = c.value;
    std::this_thread::sleep_for(50ms);
  }
  for (const char* name :
       {"capture_to_mask_ms", "stage_mask_delivery_ms", "stage_assembly_ms", "stage_queue_ms",
        "stage_cut_ms", "stage_mesh_ms", "stage_refine_ms", "stage_publish_ms", "mask_to_mesh_ms"})
    EXPECT_TRUE(g.contains(name)) << name;
  EXPECT_GE(g["stage_assembly_ms"], 0);
  EXPECT_GT(g["stage_cut_ms"], 0);
  EXPECT_GT(g["stage_mesh_ms"], 0);
  EXPECT_EQ(g["stage_refine_ms"] > 0, refine);
  EXPECT_GE(g["stage_mask_delivery_ms"], 0);
  EXPECT_LT(g["stage_mask_delivery_ms"], 1000);
  EXPECT_GE(g["mask_to_mesh_ms"], 0.5 * (g["stage_cut_ms"] + g["stage_mesh_ms"]));
  EXPECT_EQ(hull.stop(), 0) << hull.log();
}

TEST_F(HullNodeTest, MasksInSegmentsAndMeshOut) { masks_in_segments_and_mesh_out(true); }
TEST_F(HullNodeTest, RefineOffPublishesTheHalfCellMesh) { masks_in_segments_and_mesh_out(false); }

TEST_F(HullNodeTest, MissingCameraWaitsForTheDeadlineThenGoesWithout) {
  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto seg_topic = wire::Topic<studio_SegmentSet>::create(p).value();
  auto segs = wire::Reader<studio_SegmentSet>::create(p, seg_topic).value();
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(p).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(p, status_topic).value();

  auto& hull =
      spawn("hull", "hull/studio-hull",
            {"--config",
             write_config("  box: [-1.5, 0, -1.5, 1.5, 2.2, 1.5]\n  grid: 64\n  deadline_ms: 300\n"
                          "  mesh: false\n")});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));
  std::vector<int> without_last(cameras_.size() - 1);
  for (std::size_t i = 0; i < without_last.size(); ++i) without_last[i] = int(i);

  bool got = false;
  for (int attempt = 0; attempt < 10 && !got; ++attempt) {
    // Taken before the first mask is written: the node's deadline runs from that mask's arrival
    // (publishing 5 masks takes tens of ms under ASan).
    const auto sent = std::chrono::steady_clock::now();
    publish_masks(masks, 100 + attempt, 0, without_last);
    while (std::chrono::steady_clock::now() - sent < 2s && !got) {
      for (auto& s : segs.take())
        if (s.meta.valid_data) {
          got = true;
          // Not before the deadline: the node waited for the missing camera.
          EXPECT_GE(std::chrono::steady_clock::now() - sent, 250ms);
        }
      std::this_thread::sleep_for(10ms);
    }
  }
  ASSERT_TRUE(got) << hull.log();

  // The status reports the partial frames and DEGRADED.
  bool degraded = false;
  double partial = 0;
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < until && !(degraded && partial > 0)) {
    for (auto& s : status.take()) {
      if (!s.meta.valid_data) continue;
      if (s.data->state == studio_SERVICE_DEGRADED) degraded = true;
      for (const auto& c : wire::view(s.data->counters))
        if (std::string(c.name) == "frames_partial") partial = c.value;
    }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(degraded);
  EXPECT_GE(partial, 1);
  EXPECT_EQ(hull.stop(), 0);
}

// A tracked camera's calibration changes every frame. Camera 0 alternates between its rig pose
// (even frames) and one swung 25 degrees about the studio's vertical axis (odd frames), and its
// masks are rendered from that frame's pose. The calibration of frame N+1 arrives before the
// masks of frame N: the node must still cut frame N with the pose of frame N (the latest pose
// would carve the actor away in camera 0).
TEST_F(HullNodeTest, TrackedCameraIsCutWithThePoseOfItsFrame) {
  std::vector<Camera> swung = cameras_;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(25.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  swung[0].cam_from_world = cameras_[0].cam_from_world * Rigid3(turn, Eigen::Vector3d::Zero());
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::walk;
  auto swung_studio = sim::SimulatedStudio::create(swung, so).value();
  auto pose_of = [&](int64_t f) -> const std::vector<Camera>& { return f % 2 ? swung : cameras_; };

  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto cal_topic = wire::Topic<studio_CameraCalibration>::create(p).value();
  auto cals = wire::Writer<studio_CameraCalibration>::create(p, cal_topic).value();
  auto seg_topic = wire::Topic<studio_SegmentSet>::create(p).value();
  auto segs = wire::Reader<studio_SegmentSet>::create(p, seg_topic).value();
  auto& hull = spawn("hull", "hull/studio-hull",
                     {"--config", write_config("  box: [-1.5, 0, -1.5, 1.5, 2.2, 1.5]\n  grid: 96\n"
                                               "  deadline_ms: 1000\n  refine: false\n")});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));
  ASSERT_TRUE(cals.wait_for_readers(1, 10s));

  auto send_calibration = [&](int64_t f) {
    wire::Owned<studio_CameraCalibration> c;
    ASSERT_TRUE(wire::from_core(pose_of(f)[0], *c).has_value());
    c->frame = uint64_t(f);
    c->capture_ns = f;
    c->tracked = true;
    ASSERT_TRUE(cals.write(*c).has_value());
  };
  // Every camera's mask of frame f, rendered before any is sent: rendering them between writes
  // spread one frame's masks over more than the deadline on a loaded CI machine, and the frame
  // went out partial (a larger volume than the local cut's).
  auto render_masks = [&](int64_t f) {
    std::vector<RunMask> runs(cameras_.size());
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      Mask m;
      (f % 2 && c == 0 ? swung_studio : *studio_).render(int(c), f, nullptr, &m);
      runs[c] = RunMask::from_mask(m.view());
    }
    return runs;
  };
  auto send_masks = [&](int64_t f, const std::vector<RunMask>& runs) {
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      wire::Owned<studio_AlphaMask> s;
      wire::set(s->camera_id, cameras_[c].id);
      s->frame = uint64_t(f);
      s->capture_ns = f;
      wire::from_core(runs[c], studio_MASK_CODEC, *s);
      ASSERT_TRUE(masks.write(*s).has_value());
    }
  };
  auto local_volume = [&](int64_t f) {
    const std::vector<RunMask> runs = render_masks(f);
    std::vector<View> views;
    for (std::size_t c = 0; c < cameras_.size(); ++c) views.push_back({&pose_of(f)[c], &runs[c]});
    HullNodeOptions o;
    o.box = {-1.5, 0, -1.5, 1.5, 2.2, 1.5};
    o.grid = 96;
    auto h = visual_hull(o.grid_spec(), views);
    const auto actors = connected_components(*h, o.min_actor_volume);
    return actors.empty() ? 0.0 : actors[0].volume();
  };

  // Frames 41, 43, ... (camera 0 swung): calibration N, then N+1, then the masks of N. The topic
  // keeps only the newest pose per camera; the node's reader keeps a history, so N is still
  // there when the node is slow to take it (under ASan at full load it was not, before).
  // N and N+1 written back to back did not both reach the node in a quick check (the keep-last-1
  // writer may replace N before sending it; not investigated), so they are 50 ms apart.
  // The writer seeing the node's reader does not mean the node's reader has seen the writer: a
  // pose written before that is dropped, and the keep-last-1 writer has replaced it by the time
  // the node asks for it again (frame 41 was cut with pose 42 on a loaded CI machine). So frame
  // 40's pose (the rig's) is sent until the node's status counts a calibration in.
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(p).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(p, status_topic).value();
  double calibrations_in = 0;
  for (const auto until = std::chrono::steady_clock::now() + 20s;
       calibrations_in < 1 && std::chrono::steady_clock::now() < until;) {
    send_calibration(40);
    for (int k = 0; k < 10 && calibrations_in < 1; ++k) {
      std::this_thread::sleep_for(100ms);
      for (auto& s : status.take())
        if (s.meta.valid_data)
          for (const auto& c : wire::view(s.data->counters))
            if (std::string(c.name) == "calibrations_in") calibrations_in = c.value;
    }
  }
  ASSERT_GE(calibrations_in, 1) << hull.log();

  std::map<int64_t, double> got;
  for (int64_t f = 41; f < 41 + 2 * 12 && got.size() < 3; f += 2) {
    const std::vector<RunMask> runs = render_masks(f);
    send_calibration(f);
    std::this_thread::sleep_for(50ms);  // on the wire before N+1 replaces it in the writer
    send_calibration(f + 1);
    std::this_thread::sleep_for(150ms);  // both poses arrive before the masks
    send_masks(f, runs);
    const auto until = std::chrono::steady_clock::now() + 3s;
    while (std::chrono::steady_clock::now() < until && !got.count(f)) {
      for (auto& s : segs.take())
        if (s.meta.valid_data && std::string(s.data->actor_id) == "actor0" &&
            s.data->frame == uint64_t(f))
          got[f] = wire::to_core(*s.data).value().volume();
      std::this_thread::sleep_for(20ms);
    }
  }
  ASSERT_GE(got.size(), 2u) << hull.log();
  for (const auto& [f, volume] : got) {
    const double expected = local_volume(f);
    EXPECT_GT(expected, 0.05);
    EXPECT_NEAR(volume, expected, 1e-6 * expected) << "frame " << f;
  }
  EXPECT_EQ(hull.stop(), 0) << hull.log();
}

// projector_masks: true: per frame, every projector of the rig gets its viewpoint-cut actor mask
// on studio/projector/mask, stamped like the segments, equal to the library's for the same masks.
TEST_F(HullNodeTest, ProjectorMasksOut) {
  const Projector proj = sim::studio_projector(sim::Cyclorama{}, {0.5, 2.5, 3.8});
  Rig rig;
  rig.cameras = cameras_;
  rig.projectors.push_back(proj);
  ASSERT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()).has_value());
  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto pm_topic = wire::Topic<studio_ProjectorMask>::create(p).value();
  auto pms = wire::Reader<studio_ProjectorMask>::create(p, pm_topic).value();
  auto& hull = spawn("hull", "hull/studio-hull", {"--config", write_config(kProjectorMaskSection)});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));

  const std::vector<int> all = all_cameras();
  const int64_t frame = 40, capture_ns = 1'700'000'000'000'000'000;
  bool matched = false;
  int received = 0;
  for (int attempt = 0; attempt < 20 && !matched; ++attempt) {
    publish_masks(masks, frame + attempt, capture_ns + attempt, all);
    const auto until = std::chrono::steady_clock::now() + 2s;
    while (std::chrono::steady_clock::now() < until && !matched) {
      for (auto& s : pms.take()) {
        if (!s.meta.valid_data) continue;
        ++received;
        EXPECT_EQ(std::string(s.data->projector_id), "proj0");
        EXPECT_EQ(s.data->capture_ns - capture_ns, int64_t(s.data->frame) - frame);
        EXPECT_EQ(s.data->step, 2u);
        auto core = wire::to_core(*s.data);
        ASSERT_TRUE(core.has_value()) << core.error().message;
        ASSERT_EQ(core->width(), 1920);
        ASSERT_EQ(core->height(), 1080);
        // Only a mask made from every camera's mask (best-effort masks may be lost).
        if (*core == library_projector_mask(proj.camera, int64_t(s.data->frame))) matched = true;
      }
      std::this_thread::sleep_for(20ms);
    }
  }
  EXPECT_TRUE(matched) << received << " masks received, none equal to the library's\n"
                       << hull.log();
  EXPECT_EQ(pms.rejected().total(), 0u);
  EXPECT_EQ(hull.stop(), 0) << hull.log();
}

// A projector the rig does not hold joins by its own studio/projector/calibration (as
// studio-projector publishes it, transient local): its viewpoint-cut mask follows, equal to the
// library's; a refused calibration (non-finite) is counted and changes nothing.
TEST_F(HullNodeTest, ProjectorCalibrationFromTheWireJoinsTheMasks) {
  Projector proj = sim::studio_projector(sim::Cyclorama{}, {-0.5, 2.4, 3.6}, 6.0, 640, 360);
  proj.camera.id = "proj7";
  Rig rig;
  rig.cameras = cameras_;  // no projector
  ASSERT_TRUE(yaml::write_rig(rig, (dir_ / "rig.yaml").string()).has_value());
  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto cal_topic = wire::Topic<studio_ProjectorCalibration>::create(p).value();
  auto cals = wire::Writer<studio_ProjectorCalibration>::create(p, cal_topic).value();
  auto pm_topic = wire::Topic<studio_ProjectorMask>::create(p).value();
  auto pms = wire::Reader<studio_ProjectorMask>::create(p, pm_topic).value();
  // Published before the hull starts: transient local, the hull still gets it.
  wire::Owned<studio_ProjectorCalibration> c;
  ASSERT_TRUE(wire::from_core(proj, Eigen::Matrix3d::Identity(), *c).has_value());
  ASSERT_TRUE(cals.write(*c).has_value());
  auto& hull = spawn("hull", "hull/studio-hull", {"--config", write_config(kProjectorMaskSection)});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));
  wire::Owned<studio_ProjectorCalibration> bad;
  ASSERT_TRUE(wire::from_core(proj, Eigen::Matrix3d::Identity(), *bad).has_value());
  wire::set(bad->projector_id, "proj8");
  bad->t[0] = NAN;
  ASSERT_TRUE(cals.write(*bad).has_value());

  const std::vector<int> all = all_cameras();
  const int64_t frame = 60, capture_ns = 1'700'000'000'000'000'000;
  bool matched = false;
  for (int attempt = 0; attempt < 20 && !matched; ++attempt) {
    publish_masks(masks, frame + attempt, capture_ns + attempt, all);
    const auto until = std::chrono::steady_clock::now() + 2s;
    while (std::chrono::steady_clock::now() < until && !matched) {
      for (auto& s : pms.take()) {
        if (!s.meta.valid_data) continue;
        EXPECT_EQ(std::string(s.data->projector_id), "proj7");  // never the refused proj8
        auto core = wire::to_core(*s.data);
        ASSERT_TRUE(core.has_value()) << core.error().message;
        ASSERT_EQ(core->width(), 640);
        if (core->area() > 1000 &&
            *core == library_projector_mask(proj.camera, int64_t(s.data->frame)))
          matched = true;
      }
      std::this_thread::sleep_for(20ms);
    }
  }
  EXPECT_TRUE(matched) << hull.log();
  EXPECT_EQ(hull.stop(), 0) << hull.log();
}

TEST_F(HullNodeTest, BadConfigIsOneLine) {
  struct Case {
    std::string section, expect;
  } cases[] = {
      {"  box: [0, 0, 0, 1, 1]\n", "box"},
      {"  box: [0, 0, 0, 1, 1, 1]\n  grid: 3\n", "grid"},
      {"  box: [0, 0, 0, 0, 1, 1]\n", "box"},
      {"  box: [0, 0, 0, 1, 1, 1]\n  colour: red\n", "colour: unknown key"},
      {"  box: [0, 0, 0, 1, 1, 1]\n  min_cameras: 9\n", "min_cameras"},
      {"  box: [0, 0, 0, 1, 1, 1]\n  refine: maybe\n", "refine"},
      {"  box: [0, 0, 0, 1, 1, 1]\n  projector_mask_step: 0\n", "projector_mask_step"},
  };
  for (const auto& c : cases) {
    auto& p = spawn("hull", "hull/studio-hull", {"--config", write_config(c.section)});
    EXPECT_EQ(p.wait_exit(10s), 1) << c.section;
    const std::string log = p.log();
    EXPECT_NE(log.find(c.expect), std::string::npos) << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
}

}  // namespace
// A camera whose CameraState says its calibration is invalid (zoom/focus moved without a lens
// table, or a silent tracker) is left out of the cut: with camera 0 invalid and an empty mask
// from it, the hull is the other five cameras' cut; valid again, all six cut.
TEST_F(HullNodeTest, CameraWithInvalidCalibrationIsLeftOut) {
  auto p = wire::Participant::create().value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Writer<studio_AlphaMask>::create(p, mask_topic).value();
  auto state_topic = wire::Topic<studio_CameraState>::create(p).value();
  auto states = wire::Writer<studio_CameraState>::create(p, state_topic).value();
  auto seg_topic = wire::Topic<studio_SegmentSet>::create(p).value();
  auto segs = wire::Reader<studio_SegmentSet>::create(p, seg_topic).value();
  auto& hull = spawn("hull", "hull/studio-hull",
                     {"--config", write_config("  box: [-1.5, 0, -1.5, 1.5, 2.2, 1.5]\n  grid: 96\n"
                                               "  deadline_ms: 300\n  refine: false\n")});
  ASSERT_TRUE(hull.wait_ready(20s)) << hull.log();
  ASSERT_TRUE(masks.wait_for_readers(1, 10s));
  ASSERT_TRUE(states.wait_for_readers(1, 10s));
  auto set_valid = [&](bool valid) {
    wire::Owned<studio_CameraState> s;
    wire::set(s->camera_id, cameras_[0].id);
    s->state = studio_CAMERA_STREAMING;
    s->calibration_valid = valid;
    ASSERT_TRUE(states.write(*s).has_value());
    std::this_thread::sleep_for(300ms);
  };
  // Camera 0's mask: empty when `empty` (a zoomed camera whose model no longer fits).
  auto send = [&](int64_t f, bool empty) {
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      Mask m;
      studio_->render(int(c), f, nullptr, &m);
      if (c == 0 && empty) m = Mask(m.width(), m.height());
      wire::Owned<studio_AlphaMask> s;
      wire::set(s->camera_id, cameras_[c].id);
      s->frame = uint64_t(f);
      s->capture_ns = f;
      wire::from_core(RunMask::from_mask(m.view()), studio_MASK_CODEC, *s);
      ASSERT_TRUE(masks.write(*s).has_value());
    }
  };
  auto local_volume = [&](int64_t f, std::size_t first_camera) {
    std::vector<RunMask> runs(cameras_.size());
    std::vector<View> views;
    for (std::size_t c = first_camera; c < cameras_.size(); ++c) {
      Mask m;
      studio_->render(int(c), f, nullptr, &m);
      runs[c] = RunMask::from_mask(m.view());
      views.push_back({&cameras_[c], &runs[c]});
    }
    HullNodeOptions o;
    o.box = {-1.5, 0, -1.5, 1.5, 2.2, 1.5};
    o.grid = 96;
    auto h = visual_hull(o.grid_spec(), views);
    const auto actors = connected_components(*h, o.min_actor_volume);
    return actors.empty() ? 0.0 : actors[0].volume();
  };
  auto volume_of = [&](int64_t f, bool empty) -> std::optional<double> {
    for (int attempt = 0; attempt < 10; ++attempt, ++f) {
      send(f, empty);
      const auto until = std::chrono::steady_clock::now() + 1s;
      while (std::chrono::steady_clock::now() < until) {
        for (auto& s : segs.take())
          if (s.meta.valid_data && std::string(s.data->actor_id) == "actor0" &&
              s.data->frame == uint64_t(f)) {
            const double v = wire::to_core(*s.data).value().volume();
            EXPECT_NEAR(v, local_volume(f, empty ? 1 : 0), 1e-6 * v) << "frame " << f;
            return v;
          }
        std::this_thread::sleep_for(20ms);
      }
    }
    return std::nullopt;
  };
  set_valid(false);
  const auto five = volume_of(60, true);
  ASSERT_TRUE(five) << hull.log();
  set_valid(true);
  const auto six = volume_of(80, false);
  ASSERT_TRUE(six) << hull.log();
  EXPECT_GT(*five, *six);  // one camera fewer cuts less away
  EXPECT_EQ(hull.stop(), 0) << hull.log();
}

}  // namespace studio::hull

// The example configs of a complete studio (deploy/examples/studio/) are correct: started as the
// systemd units and the demo start them (one process per config, straight from that folder), the
// services come up (READY=1), the cameras' published calibrations are exactly rig.yaml's (so the
// hull cuts with the cameras the simulator renders), actor meshes and head poses come out, and
// SIGTERM ends every service with exit status 0. Both variants: keying in the capture servers,
// and separate keyer services.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "harness/fixture.h"
#include "wire/convert.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"
#include "yaml_io/rig_yaml.h"

namespace studio {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::string kExamples = STUDIO_SOURCE_DIR "/deploy/examples/studio";

class ExampleStudio : public testing::ProcessTest {
 protected:
  // Starts tracker, hull, the keyers (if any) and the six cameras; all must report ready.
  void start_studio(const std::string& capture_dir, const std::vector<std::string>& keyers) {
    auto& tracker =
        spawn("tracker", "tracker/studio-tracker", {"--config", kExamples + "/tracker.yaml"});
    auto& hull = spawn("hull", "hull/studio-hull", {"--config", kExamples + "/hull.yaml"});
    std::vector<testing::Process*> all = {&tracker, &hull};
    for (const auto& k : keyers)
      all.push_back(
          &spawn(k, "keyer/studio-keyer", {"--config", capture_dir + "/keyer-" + k + ".yaml"}));
    for (int i = 0; i < 6; ++i) {
      const std::string cam = "cam" + std::to_string(i);
      all.push_back(&spawn(cam, "capture/studio-capture",
                           {"--config", capture_dir + "/capture-" + cam + ".yaml"}));
    }
    for (auto* p : all) ASSERT_TRUE(p->wait_ready(30s)) << p->name() << "\n" << p->log();
  }

  // Calibrations of cam0..cam5 equal rig.yaml's cameras; then a mesh of actor0 and a head pose
  // of `actor` that is a frame's update (not a keep-alive) arrive.
  void expect_studio_output() {
    auto rig = yaml::read_rig(kExamples + "/rig.yaml");
    ASSERT_TRUE(rig.has_value()) << rig.error().message;
    ASSERT_EQ(rig->cameras.size(), 6u);
    auto p = wire::Participant::create().value();
    auto cals = wire::Subscription<studio_CameraCalibration>::create(p).value();
    auto meshes = wire::Subscription<studio_ActorMesh>::create(p).value();
    auto heads = wire::Subscription<studio_HeadPose>::create(p, {}, 16).value();
    std::map<std::string, Camera> published;
    bool mesh = false, head = false;
    const auto until = Clock::now() + 30s;
    while (Clock::now() < until && !(published.size() == 6 && mesh && head)) {
      cals->visit([&](const studio_CameraCalibration& s, const wire::SampleMeta& m) {
        if (auto c = wire::to_core(s); m.valid_data && c)
          published.insert_or_assign(s.camera_id, *c);
      });
      meshes->visit([&](const studio_ActorMesh& s, const wire::SampleMeta& m) {
        if (m.valid_data && std::string(s.actor_id) == "actor0" && s.triangles._length > 300)
          mesh = true;
      });
      heads->visit([&](const studio_HeadPose& s, const wire::SampleMeta& m) {
        // A frame's update carries that frame's capture instant (25 fps, epoch 0: the middle of
        // the frame period, capture/sim_source.h); keep-alives coast in between.
        if (m.valid_data && std::string(s.actor_id) == "actor" &&
            s.capture_ns == int64_t(s.frame) * 40'000'000 + 20'000'000 && s.confidence > 0.3 &&
            s.position[1] > 1.2 && s.position[1] < 2.0)
          head = true;
      });
      std::this_thread::sleep_for(50ms);
    }
    ASSERT_EQ(published.size(), 6u) << "calibrations published by the capture servers";
    for (const Camera& r : rig->cameras) {
      SCOPED_TRACE(r.id);
      ASSERT_TRUE(published.contains(r.id));
      const Camera& c = published.at(r.id);
      EXPECT_EQ(c.width, r.width);
      EXPECT_EQ(c.height, r.height);
      EXPECT_NEAR(c.intrinsics.fx, r.intrinsics.fx, 1e-9);
      EXPECT_NEAR(c.intrinsics.fy, r.intrinsics.fy, 1e-9);
      EXPECT_NEAR(c.intrinsics.cx, r.intrinsics.cx, 1e-9);
      EXPECT_NEAR(c.intrinsics.cy, r.intrinsics.cy, 1e-9);
      EXPECT_LT((c.cam_from_world.matrix() - r.cam_from_world.matrix()).cwiseAbs().maxCoeff(),
                1e-9);
    }
    EXPECT_TRUE(mesh) << "no actor0 mesh from the hull within 30 s";
    EXPECT_TRUE(head) << "no head update of `actor` from the tracker within 30 s";
  }

  void expect_clean_stop() {
    for (auto& p : processes_) EXPECT_EQ(p.stop(10s), 0) << p.name() << "\n" << p.log();
  }
};

TEST_F(ExampleStudio, InProcessKeying) {
  start_studio(kExamples, {});
  if (HasFatalFailure()) return;
  expect_studio_output();
  expect_clean_stop();
}

TEST_F(ExampleStudio, SeparateKeyerServices) {
  start_studio(kExamples + "/separate-keyer", {"keyer0", "keyer1"});
  if (HasFatalFailure()) return;
  expect_studio_output();
  expect_clean_stop();
}

}  // namespace
}  // namespace studio

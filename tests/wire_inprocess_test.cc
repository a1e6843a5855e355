// The wire layer within one process (one participant, local delivery, private domain): loans
// returned when a visitor throws, rejections counted once under read(), the guard condition
// waking a WaitSet, dispose notices.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "harness/fixture.h"
#include "harness/wire_samples.h"
#include "wire/endpoint.h"
#include "wire/pubsub.h"

namespace studio::testing {
namespace {

using namespace std::chrono_literals;

class WireInProcess : public ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    p_.emplace(wire::Participant::create().value());
  }
  void TearDown() override {
    p_.reset();
    ProcessTest::TearDown();
  }
  std::optional<wire::Participant> p_;
};

TEST_F(WireInProcess, VisitorExceptionsReturnTheLoanAndPropagate) {
  auto topic = wire::Topic<studio_CameraControl>::create(*p_).value();
  auto writer = wire::Writer<studio_CameraControl>::create(*p_, topic).value();
  auto reader = wire::Reader<studio_CameraControl>::create(*p_, topic).value();
  for (int round = 0; round < 50; ++round) {
    for (int seed = 0; seed < 3; ++seed)
      ASSERT_TRUE(writer.write(*make<studio_CameraControl>(seed)));
    EXPECT_THROW(reader.visit([](const studio_CameraControl&, const wire::SampleMeta&) {
      throw std::runtime_error("visitor failed");
    }),
                 std::runtime_error);
  }
  // The reader still lends and delivers after 50 aborted visits.
  ASSERT_TRUE(writer.write(*make<studio_CameraControl>(1)));
  std::size_t n = reader.visit([](const studio_CameraControl& c, const wire::SampleMeta&) {
    EXPECT_EQ(wire::str(c.camera_id), "cam1");
  });
  EXPECT_EQ(n, 1u);
}

TEST_F(WireInProcess, RejectionsAreCountedOnceWhenSamplesAreReadRepeatedly) {
  auto topic = wire::Topic<studio_SceneNode>::create(*p_).value();
  auto writer = wire::Writer<studio_SceneNode>::create(*p_, topic).value();
  auto reader = wire::Reader<studio_SceneNode>::create(*p_, topic).value();
  auto bad = make<studio_SceneNode>(1);
  bad->parent_from_node[0] = INFINITY;
  ASSERT_TRUE(writer.write(*bad));
  ASSERT_TRUE(writer.write(*make<studio_SceneNode>(2)));
  for (int i = 0; i < 3; ++i) {
    auto got = reader.read();
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(wire::str(got[0].data->node_id), "node2");
  }
  EXPECT_EQ(reader.rejected().total(), 1u);
  EXPECT_EQ(reader.rejected()[wire::Reject::non_finite], 1u);
}

TEST_F(WireInProcess, GuardConditionWakesTheWaitSet) {
  auto guard = wire::GuardCondition::create(*p_).value();
  auto ws = wire::WaitSet::create(*p_).value();
  ASSERT_TRUE(ws.attach(guard, 7));
  EXPECT_TRUE(ws.wait(20ms).empty());
  std::thread t([&] {
    std::this_thread::sleep_for(50ms);
    guard.trigger();
  });
  const auto t0 = std::chrono::steady_clock::now();
  auto woke = ws.wait(10s);
  t.join();
  ASSERT_EQ(woke.size(), 1u);
  EXPECT_EQ(woke[0], 7);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
  EXPECT_TRUE(guard.take());
  EXPECT_FALSE(guard.take());
}

TEST_F(WireInProcess, ReaderWakesWaitSetAndSeesDisposal) {
  auto topic = wire::Topic<studio_SceneNode>::create(*p_).value();
  auto writer = wire::Writer<studio_SceneNode>::create(*p_, topic).value();
  auto reader = wire::Reader<studio_SceneNode>::create(*p_, topic).value();
  auto ws = wire::WaitSet::create(*p_).value();
  ASSERT_TRUE(ws.attach(reader, 3));
  auto node = make<studio_SceneNode>(2);
  ASSERT_TRUE(writer.write(*node));
  auto woke = ws.wait(5s);
  ASSERT_EQ(woke.size(), 1u);
  EXPECT_EQ(woke[0], 3);
  auto got = reader.take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_TRUE(same(*got[0].data, *node));
  EXPECT_TRUE(got[0].meta.alive);
  ASSERT_TRUE(writer.dispose(*node));
  ASSERT_EQ(ws.wait(5s).size(), 1u);
  got = reader.take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].meta.valid_data);
  EXPECT_TRUE(got[0].meta.disposed);
  EXPECT_EQ(wire::str(got[0].data->node_id), "node2");  // key fields of the notice
  EXPECT_TRUE(ws.wait(50ms).empty());
}

// A reader's own history depth: the calibration topic keeps the last sample per camera, so a
// reader that falls behind sees only the newest pose; with a deeper history it sees every one.
TEST_F(WireInProcess, ReaderHistoryDepthKeepsSamplesTheTopicDepthWouldReplace) {
  auto topic = wire::Topic<studio_CameraCalibration>::create(*p_).value();
  auto writer = wire::Writer<studio_CameraCalibration>::create(*p_, topic).value();
  auto shallow = wire::Reader<studio_CameraCalibration>::create(*p_, topic).value();
  auto deep = wire::Reader<studio_CameraCalibration>::create(*p_, topic, 8).value();
  auto sample = make<studio_CameraCalibration>(0);
  for (uint64_t frame = 1; frame <= 5; ++frame) {
    sample->frame = frame;
    ASSERT_TRUE(writer.write(*sample));
  }
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  std::vector<uint64_t> frames;
  while (frames.size() < 5 && std::chrono::steady_clock::now() < deadline) {
    for (auto& s : deep.take()) frames.push_back(s.data->frame);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(frames, (std::vector<uint64_t>{1, 2, 3, 4, 5}));
  auto latest = shallow.take();
  ASSERT_EQ(latest.size(), 1u);
  EXPECT_EQ(latest[0].data->frame, 5u);
}

// The data-available callback sees every valid sample (and no rejected one), can be removed, and
// a reader deleted while samples keep arriving neither calls into a freed callback (ASan would
// report it) nor runs the callback on a half-deleted reader.
TEST_F(WireInProcess, DataAvailableCallbackDeliversValidSamplesUntilRemoved) {
  auto topic = wire::Topic<studio_SceneNode>::create(*p_).value();
  auto writer = wire::Writer<studio_SceneNode>::create(*p_, topic).value();
  auto reader = wire::Reader<studio_SceneNode>::create(*p_, topic).value();
  std::mutex mu;
  std::condition_variable cv;
  std::vector<std::string> seen;
  ASSERT_TRUE(reader.on_data_available([&] {
    reader.visit([&](const studio_SceneNode& n, const wire::SampleMeta& m) {
      if (!m.valid_data) return;
      std::lock_guard lock(mu);
      seen.emplace_back(wire::str(n.node_id));
      cv.notify_all();
    });
  }));
  auto bad = make<studio_SceneNode>(1);
  bad->parent_from_node[0] = INFINITY;
  ASSERT_TRUE(writer.write(*bad));
  for (int seed = 2; seed <= 4; ++seed) ASSERT_TRUE(writer.write(*make<studio_SceneNode>(seed)));
  {
    std::unique_lock lock(mu);
    ASSERT_TRUE(cv.wait_for(lock, 5s, [&] { return seen.size() >= 3; }));
    EXPECT_EQ(seen.size(), 3u);
  }
  EXPECT_EQ(reader.rejected().total(), 1u);

  // Removed: samples stay in the reader for an explicit take.
  ASSERT_TRUE(reader.on_data_available(nullptr));
  ASSERT_TRUE(writer.write(*make<studio_SceneNode>(5)));
  std::this_thread::sleep_for(100ms);
  {
    std::lock_guard lock(mu);
    EXPECT_EQ(seen.size(), 3u);
  }
  EXPECT_EQ(reader.take().size(), 1u);

  // A reader with a callback destroyed while a writer is busy.
  std::atomic<int> calls{0};
  std::atomic<bool> stop{false};
  std::thread pump([&] {
    for (int i = 0; !stop; ++i) (void)writer.write(*make<studio_SceneNode>(i % 7));
  });
  for (int round = 0; round < 20; ++round) {
    auto r = std::make_unique<wire::Reader<studio_SceneNode>>(
        wire::Reader<studio_SceneNode>::create(*p_, topic).value());
    auto* raw = r.get();
    ASSERT_TRUE(r->on_data_available([raw, &calls] {
      raw->visit([&](const studio_SceneNode&, const wire::SampleMeta&) { ++calls; });
    }));
    std::this_thread::sleep_for(2ms);
    r.reset();
  }
  stop = true;
  pump.join();
  EXPECT_GT(calls.load(), 0);
}

// A node's endpoints come from gather(): all or the first error, and the bundled publication
// and subscription talk to each other.
TEST_F(WireInProcess, GatherBuildsEndpointsOrReturnsTheFirstError) {
  struct Io {
    wire::Publication<studio_HeadPose> out;
    wire::Subscription<studio_HeadPose> in;
  };
  auto io = wire::gather([](auto&&... e) { return Io{std::move(e)...}; },
                         wire::Publication<studio_HeadPose>::create(*p_),
                         wire::Subscription<studio_HeadPose>::create(*p_));
  ASSERT_TRUE(io) << io.error().message;
  ASSERT_TRUE(io->out->write(*make<studio_HeadPose>(3)));
  EXPECT_EQ(io->in->take().size(), 1u);

  auto failed = wire::gather([](int a, int b, int c) { return a + b + c; }, Expected<int>(1),
                             Expected<int>(fail("second")), Expected<int>(fail("third")));
  ASSERT_FALSE(failed);
  EXPECT_EQ(failed.error().message, "second");
  EXPECT_EQ(wire::gather([](int a, int b) { return a + b; }, Expected<int>(1), Expected<int>(2)),
            3);
}

TEST_F(WireInProcess, BadConfigGivesOneLineError) {
  auto p =
      wire::Participant::create(231, "<CycloneDDS><Domain><NoSuchElement/></Domain></CycloneDDS>");
  ASSERT_FALSE(p.has_value());
  EXPECT_NE(p.error().message.find("dds: create domain 231"), std::string::npos)
      << p.error().message;
  EXPECT_EQ(p.error().message.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace studio::testing

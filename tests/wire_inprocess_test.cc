// The wire layer within one process (one participant, local delivery, private domain): loans
// returned when a visitor throws, rejections counted once under read(), the guard condition
// waking a WaitSet, dispose notices.

#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "harness/fixture.h"
#include "harness/wire_samples.h"
#include "wire/endpoint.h"

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

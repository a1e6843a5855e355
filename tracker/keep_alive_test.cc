// The tracker service's keep-alive (tracker/keep_alive.h): coasting per tick, the drop to
// confidence 0 after max_missed ticks, capture times on the source's clock, restart on a frame.
#include "tracker/keep_alive.h"

#include <gtest/gtest.h>

namespace studio::tracker {
namespace {

using namespace std::chrono_literals;
using Clock = KeepAlive::Clock;

HeadPose moving_head() {
  HeadPose p;
  p.actor_id = 3;
  p.position = {0, 1.6, 0};
  p.velocity = {1, 0, -0.5};
  p.confidence = 0.9;
  p.capture_ns = 5'000'000'000;
  return p;
}

TEST(KeepAlive, RestPoseUntilTheFirstFrame) {
  HeadTrackerOptions o;
  const auto t0 = Clock::now();
  const HeadPose rest = HeadTracker::create(o).value().primary();
  KeepAlive k(o, 10, rest, t0);
  EXPECT_EQ(k.due(), t0 + 100ms);
  EXPECT_TRUE(k.lost());
  const HeadPose p = k.tick(t0 + 100ms);
  EXPECT_EQ(p.position, o.rest_position);
  EXPECT_EQ(p.confidence, 0);
  EXPECT_EQ(p.capture_ns, rest.capture_ns);  // no source clock yet
  EXPECT_EQ(k.frame_number(), 0u);
  EXPECT_EQ(k.due(), t0 + 200ms);
}

TEST(KeepAlive, CoastsPerTickThenDropsAfterMaxMissed) {
  HeadTrackerOptions o;
  o.max_missed = 3;
  o.coast_decay = 0.5;
  const auto t0 = Clock::now();
  KeepAlive k(o, 10, HeadPose{}, t0);
  const HeadPose head = moving_head();
  k.frame(head, 42, t0);
  EXPECT_FALSE(k.lost());
  EXPECT_EQ(k.due(), t0 + 100ms);

  Eigen::Vector3d position = head.position, velocity = head.velocity;
  double confidence = head.confidence;
  for (int tick = 1; tick <= 3; ++tick) {
    const auto now = t0 + tick * 100ms;
    const HeadPose p = k.tick(now);
    position += velocity * 0.1;
    velocity *= 0.5;
    confidence *= 0.5;
    EXPECT_TRUE(p.position.isApprox(position, 1e-12)) << tick;
    EXPECT_TRUE(p.velocity.isApprox(velocity, 1e-12)) << tick;
    EXPECT_DOUBLE_EQ(p.confidence, confidence) << tick;
    EXPECT_EQ(p.actor_id, head.actor_id);
    EXPECT_EQ(p.capture_ns, head.capture_ns + tick * 100'000'000);  // predicted-for instant
    EXPECT_EQ(k.frame_number(), 42u);                               // the source's last frame
  }
  // Tick max_missed + 1: lost; the position stays from then on.
  const HeadPose lost = k.tick(t0 + 400ms);
  EXPECT_EQ(lost.confidence, 0);
  EXPECT_TRUE(lost.velocity.isZero());
  EXPECT_TRUE(lost.position.isApprox(position, 1e-12));
  EXPECT_TRUE(k.lost());
  EXPECT_TRUE(k.tick(t0 + 500ms).position.isApprox(position, 1e-12));

  // A real frame starts over.
  HeadPose again = moving_head();
  again.capture_ns = 9'000'000'000;
  k.frame(again, 50, t0 + 550ms);
  EXPECT_FALSE(k.lost());
  EXPECT_EQ(k.due(), t0 + 650ms);
  const HeadPose p = k.tick(t0 + 650ms);
  EXPECT_DOUBLE_EQ(p.confidence, 0.45);
  EXPECT_EQ(p.capture_ns, 9'100'000'000);
  EXPECT_EQ(k.frame_number(), 50u);
}

TEST(KeepAlive, ALostFrameIsNotRevived) {
  HeadTrackerOptions o;
  const auto t0 = Clock::now();
  KeepAlive k(o, 2, HeadPose{}, t0);
  HeadPose gone = moving_head();
  gone.confidence = 0;  // the tracker's fallback pose
  k.frame(gone, 7, t0);
  EXPECT_TRUE(k.lost());
  const HeadPose p = k.tick(t0 + 500ms);
  EXPECT_EQ(p.confidence, 0);
  EXPECT_TRUE(p.velocity.isZero());
  EXPECT_EQ(p.position, gone.position);  // no drift on a lost head
}

}  // namespace
}  // namespace studio::tracker

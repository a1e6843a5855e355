// Loop liveness (runtime/liveness.h), the bookkeeping behind the watchdog's view of the service
// loops: a loop counts as stalled only when its last turn is older than the bound; the worst one
// is named; a detached loop no longer counts.
#include "runtime/liveness.h"

#include <gtest/gtest.h>

namespace studio::runtime {
namespace {

using namespace std::chrono_literals;

TEST(Liveness, StalledOnlyPastTheBoundAndNamesTheLongestSilentLoop) {
  Liveness liveness(500ms);
  EXPECT_EQ(liveness.turn_period(), 125ms);
  const auto t0 = SteadyClock::now();
  EXPECT_FALSE(liveness.stalled(t0 + 1h));  // nothing attached: never stalled
  auto hull = liveness.attach("hull");
  auto scene = liveness.attach("scene");
  hull->turn(t0);
  scene->turn(t0 + 200ms);
  EXPECT_FALSE(liveness.stalled(t0 + 500ms));  // exactly the bound: still alive
  auto s = liveness.stalled(t0 + 600ms);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->name, "hull");
  EXPECT_EQ(s->silent, 600ms);
  s = liveness.stalled(t0 + 800ms);  // both past the bound: the longest silent one
  ASSERT_TRUE(s);
  EXPECT_EQ(s->name, "hull");
  hull->turn(t0 + 800ms);  // hull came round: scene (silent 0.6 s) is the stalled one now
  s = liveness.stalled(t0 + 800ms);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->name, "scene");
  liveness.detach(scene);  // a stopped loop no longer counts
  EXPECT_FALSE(liveness.stalled(t0 + 800ms));
  EXPECT_TRUE(liveness.stalled(t0 + 1400ms));
}

}  // namespace
}  // namespace studio::runtime

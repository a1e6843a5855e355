// Randomized: long sequences of random commands, valid and invalid mixed. After every command the
// invariants hold and a refused command left the state unchanged; replaying the log on a fresh
// scene gives the same hash; serialise -> deserialise gives the same hash.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scene/scene.h"
#include "scene/serialize.h"
#include "scene_testing/random_commands.h"

using namespace studio::scene;

class RandomCommands : public ::testing::TestWithParam<unsigned> {};

TEST_P(RandomCommands, InvariantsReplayAndRoundTrip) {
  studio::scene::testing::RandomCommandSource source(GetParam());
  Scene scene;
  std::vector<Command> log;
  std::size_t applied = 0, rejected = 0;
  for (int i = 0; i < 3000; ++i) {
    const Command c = source.next(scene);
    const auto before = serialize(scene);
    if (scene.apply(c)) {
      ++applied;
    } else {
      ++rejected;
      ASSERT_EQ(serialize(scene), before) << "refused command " << i << " changed the scene";
    }
    log.push_back(c);
    auto inv = scene.check_invariants();
    ASSERT_TRUE(inv) << "after command " << i << " (" << command_name(c.op) << "): " << inv.error().message;
    if (i % 500 == 499) {
      auto back = deserialize(serialize(scene));
      ASSERT_TRUE(back) << back.error().message;
      EXPECT_EQ(back->state_hash(), scene.state_hash());
    }
  }
  // Both outcomes must be exercised, and the scene must not be trivial.
  EXPECT_GT(applied, 1000u);
  EXPECT_GT(rejected, 300u);
  EXPECT_GT(scene.nodes().size(), 10u);

  Scene again;
  const ReplayResult r = replay(again, log);
  EXPECT_EQ(r.applied, applied);
  EXPECT_EQ(r.rejected, rejected);
  EXPECT_EQ(again.state_hash(), scene.state_hash());

  // The hash tells different states apart: drop one applied state-changing command.
  Scene other;
  std::vector<Command> shorter = log;
  for (std::size_t i = shorter.size(); i-- > 0;) {
    if (std::holds_alternative<AddNode>(shorter[i].op)) {
      shorter.erase(shorter.begin() + static_cast<long>(i));
      break;
    }
  }
  replay(other, shorter);
  EXPECT_NE(other.state_hash(), scene.state_hash());
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomCommands, ::testing::Values(1u, 2u, 3u, 42u, 2026u));

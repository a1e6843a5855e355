// MeshInbox (projector/mesh_inbox.h): the newest undrawn mesh of each actor reaches the planner,
// older undrawn ones are dropped and said so, bad or out-of-order meshes are refused, a disposed
// actor leaves the planner even when a new mesh of it follows.
#include "projector/mesh_inbox.h"

#include <gtest/gtest.h>

namespace studio::projector {
namespace {

ActorMesh tetra(float x, int64_t capture_ns) {
  ActorMesh m;
  m.vertices = {{x, 1, 0}, {x + 0.1f, 1, 0}, {x, 1.1f, 0}, {x, 1, 0.1f}};
  m.triangles = {{{0, 2, 1}}, {{0, 1, 3}}, {{0, 3, 2}}, {{1, 2, 3}}};
  m.capture_ns = capture_ns;
  return m;
}

constexpr int64_t kT = 1'700'000'000'000'000'000, kDt = 40'000'000;

TEST(MeshInbox, NewestMeshWinsAndDropsAreReported) {
  MeshInbox inbox;
  EXPECT_FALSE(inbox.has_meshes());
  auto first = inbox.offer("a", 1, tetra(0, kT));
  ASSERT_TRUE(first);
  EXPECT_FALSE(*first);  // nothing replaced
  auto second = inbox.offer("a", 2, tetra(0.5f, kT + kDt));
  ASSERT_TRUE(second);
  EXPECT_TRUE(*second);  // frame 1 was never drawn: dropped
  ASSERT_TRUE(inbox.offer("b", 2, tetra(2, kT + kDt)));
  EXPECT_TRUE(inbox.has_meshes());

  MeshInbox::Taken taken = inbox.take();
  EXPECT_FALSE(inbox.has_meshes());
  ASSERT_EQ(taken.meshes.size(), 2u);
  EXPECT_EQ(taken.meshes.at("a").frame, 2u);
  EXPECT_FLOAT_EQ(taken.meshes.at("a").mesh.vertices[0].x(), 0.5f);

  MaskPlanner planner;
  EXPECT_EQ(apply(std::move(taken), planner), 0);
  EXPECT_EQ(planner.actors(), 2u);
  auto plan = planner.plan(kT + 2 * kDt);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->newest_frame, 2u);
}

TEST(MeshInbox, RefusesBadAndOutOfOrderMeshesAndDisposesActors) {
  MeshInbox inbox;
  ASSERT_TRUE(inbox.offer("a", 5, tetra(0, kT)));
  EXPECT_FALSE(inbox.offer("a", 4, tetra(0, kT - kDt)));  // older
  EXPECT_FALSE(inbox.offer("a", 5, tetra(0, kT)));        // the same capture again
  ActorMesh bad = tetra(0, kT + kDt);
  bad.triangles[0][1] = 99;
  auto refused = inbox.offer("a", 6, bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("names vertex 99"), std::string::npos);
  EXPECT_FALSE(inbox.offer("a", 6, ActorMesh{}));  // empty

  MaskPlanner planner;
  EXPECT_EQ(apply(inbox.take(), planner), 0);
  EXPECT_EQ(planner.actors(), 1u);

  // Disposed, then back with a mesh captured before its last one (a restarted hull): the planner
  // forgets the old actor first, so the new mesh is accepted.
  inbox.dispose("a");
  EXPECT_FALSE(inbox.has_meshes());
  ASSERT_TRUE(inbox.offer("a", 1, tetra(1, kT - 10 * kDt)));
  EXPECT_EQ(apply(inbox.take(), planner), 0);
  ASSERT_EQ(planner.actors(), 1u);
  EXPECT_EQ(planner.plan(kT)->newest_frame, 1u);

  inbox.dispose("a");
  EXPECT_EQ(apply(inbox.take(), planner), 0);
  EXPECT_EQ(planner.actors(), 0u);

  // Positive control of the refusal count: the planner refuses a mesh the inbox let through only
  // when its own state disagrees (it saw a newer mesh of the actor directly).
  ASSERT_TRUE(planner.set_mesh("c", 9, tetra(0, kT + 5 * kDt)));
  ASSERT_TRUE(inbox.offer("c", 8, tetra(0, kT + 4 * kDt)));
  std::string error;
  EXPECT_EQ(apply(inbox.take(), planner, &error), 1);
  EXPECT_NE(error.find("not after"), std::string::npos);
}

}  // namespace
}  // namespace studio::projector

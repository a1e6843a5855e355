// The projector's scene in two layers (projector/scene_layers.h): a moving node takes its subtree
// into the moving layer; lights are in both; ancestors of moving nodes are plain groups there; the
// still version holds while only moving nodes change and changes with any still node; a moving
// light is not split.
#include <gtest/gtest.h>

#include "projector/scene_layers.h"

namespace studio::projector {
namespace {

scene::Node node(const std::string& id, const std::string& parent, scene::NodeKind kind,
                 double x = 0) {
  scene::Node n;
  n.id = id;
  n.parent = parent;
  n.kind = kind;
  if (kind == scene::NodeKind::model) n.asset.path = "a.glb";
  n.local.translation = Eigen::Vector3d(x, 0, 0);
  return n;
}

scene::Scene museum(double flyer_x, double wall_x = 0) {
  scene::Scene s;
  for (const auto& n :
       {node("set", "", scene::NodeKind::group, 1),
        node("set/wall", "set", scene::NodeKind::model, wall_x),
        node("set/arm", "set", scene::NodeKind::group, flyer_x),
        node("set/arm/flyer", "set/arm", scene::NodeKind::model, 0.5),
        node("set/sun", "set", scene::NodeKind::light)})
    EXPECT_TRUE(s.apply({0, scene::AddNode{n}})) << n.id;
  return s;
}

TEST(SceneLayers, MovingSubtreeLeavesTheStillLayerWhichKeepsItsVersion) {
  const std::set<scene::NodeId> moving{"set/arm"};
  const SceneLayers a = split_scene(museum(0.0), moving);
  EXPECT_FALSE(a.moving_light);
  EXPECT_EQ(a.moving_nodes, 2u);
  EXPECT_TRUE(a.still.find("set/wall"));
  EXPECT_TRUE(a.still.find("set/sun"));
  EXPECT_FALSE(a.still.find("set/arm"));
  EXPECT_FALSE(a.still.find("set/arm/flyer"));
  ASSERT_TRUE(a.moving.find("set/arm/flyer"));
  ASSERT_TRUE(a.moving.find("set"));
  EXPECT_EQ(a.moving.find("set")->kind, scene::NodeKind::group);
  EXPECT_TRUE(a.moving.find("set/sun"));  // lit alike
  EXPECT_FALSE(a.moving.find("set/wall"));
  // World transforms are those of the whole scene.
  const scene::Scene all = museum(0.0);
  EXPECT_TRUE(a.moving.world_from_node("set/arm/flyer")->isApprox(
      *all.world_from_node("set/arm/flyer")));
  // The flyer moves: same still version; the wall moves: another.
  EXPECT_EQ(split_scene(museum(2.0), moving).still_version, a.still_version);
  EXPECT_NE(split_scene(museum(0.0, 0.1), moving).still_version, a.still_version);
  // Nothing moving: everything still, the moving layer holds only the lights (and ancestors).
  const SceneLayers none = split_scene(all, {});
  EXPECT_EQ(none.still.nodes().size(), 5u);
  EXPECT_EQ(none.moving_nodes, 0u);
}

TEST(SceneLayers, MovingLightIsNotSplit) {
  const SceneLayers a = split_scene(museum(0.0), {"set/sun"});
  EXPECT_TRUE(a.moving_light);
  EXPECT_EQ(a.still.nodes().size(), 5u);
  EXPECT_TRUE(a.moving.nodes().empty());
  // A light under a moving group moves too.
  scene::Scene s = museum(0.0);
  ASSERT_TRUE(
      s.apply({0, scene::AddNode{node("set/arm/lamp", "set/arm", scene::NodeKind::light)}}));
  EXPECT_TRUE(split_scene(s, {"set/arm"}).moving_light);
}

}  // namespace
}  // namespace studio::projector

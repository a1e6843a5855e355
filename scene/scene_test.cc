// Scene: commands (each refusal beside a positive control), world transforms, change tracking,
// animation on the scene clock, serialisation.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "scene/scene.h"
#include "scene/serialize.h"

using namespace studio::scene;

namespace {

Node group(const std::string& id, const std::string& parent = "",
           Eigen::Vector3d t = Eigen::Vector3d::Zero()) {
  Node n;
  n.id = id;
  n.parent = parent;
  n.local.translation = t;
  return n;
}

Command at(std::int64_t frame, CommandOp op) { return Command{frame, std::move(op)}; }

void ok(Scene& s, const Command& c) {
  auto r = s.apply(c);
  ASSERT_TRUE(r) << r.error().message;
}

// Refused, and the scene is bit-for-bit unchanged.
void refused(Scene& s, const Command& c, const std::string& words) {
  const auto before = serialize(s);
  auto r = s.apply(c);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find(words), std::string::npos) << r.error().message;
  EXPECT_EQ(serialize(s), before);
}

Animation slide(const std::string& name, const std::string& node) {
  Animation a;
  a.name = name;
  a.mode = PlayMode::loop;
  Track t;
  t.node = node;
  t.times = {0, 2};
  t.values = {{0, 0, 0, 0}, {4, 0, 0, 0}};
  a.tracks.push_back(t);
  return a;
}

}  // namespace

TEST(Scene, WorldFromNodeComposesTheParentChain) {
  Scene s;
  ok(s, at(0, AddNode{group("a", "", {1, 0, 0})}));
  Node b = group("b", "a", {0, 2, 0});
  b.local.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  b.local.scale = {2, 2, 2};
  ok(s, at(0, AddNode{b}));
  ok(s, at(0, AddNode{group("c", "b", {1, 0, 0})}));
  const Eigen::Matrix4d w = *s.world_from_node("c");
  // c's origin: a(1,0,0) + b(0,2,0) + R_y(90) * 2 * (1,0,0) = (1, 2, -2).
  EXPECT_TRUE(w.col(3).head<3>().isApprox(Eigen::Vector3d(1, 2, -2), 1e-12));
  std::vector<Eigen::Matrix4d> all;
  s.world_from_nodes(all);
  ASSERT_EQ(all.size(), 3u);
  for (std::size_t i = 0; i < s.order().size(); ++i)
    EXPECT_TRUE(all[i].isApprox(*s.world_from_node(s.order()[i]->id), 1e-12));
  EXPECT_FALSE(s.world_from_node("nope"));
}

TEST(Scene, AddNodeRefusals) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  refused(s, at(0, AddNode{group("a")}), "exists");
  refused(s, at(0, AddNode{group("b", "ghost")}), "unknown parent");
  refused(s, at(0, AddNode{group("")}), "empty");
  Node nan = group("n");
  nan.local.translation.x() = NAN;
  refused(s, at(0, AddNode{nan}), "not finite");
  Node flat = group("f");
  flat.local.scale.y() = 0;
  refused(s, at(0, AddNode{flat}), "zero");
  Node model = group("m");
  model.kind = NodeKind::model;
  refused(s, at(0, AddNode{model}), "asset");
  model.asset.path = "x.glb";
  ok(s, at(0, AddNode{model}));
  refused(s, at(-1, AddNode{group("late")}), "frame");
  EXPECT_TRUE(s.check_invariants());
}

TEST(Scene, SetTransformRefusesNanAndUnknownNodes) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  Transform t;
  t.translation = {1, 2, 3};
  ok(s, at(5, SetTransform{"a", t}));
  EXPECT_EQ(s.find("a")->local.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.find("a")->frame, 5);
  t.rotation.coeffs() << 0, 0, NAN, 1;
  refused(s, at(6, SetTransform{"a", t}), "rotation is not finite");
  refused(s, at(6, SetTransform{"zz", Transform{}}), "unknown node 'zz'");
}

TEST(Scene, ReparentingRefusesCycles) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  ok(s, at(0, AddNode{group("b", "a")}));
  ok(s, at(0, AddNode{group("c", "b")}));
  refused(s, at(0, SetParent{"a", "c"}), "cycle");
  refused(s, at(0, SetParent{"a", "a"}), "cycle");
  ok(s, at(0, SetParent{"c", ""}));
  ok(s, at(0, SetParent{"a", "c"}));
  EXPECT_EQ(s.order().front()->id, "c");
  EXPECT_TRUE(s.check_invariants());
}

TEST(Scene, RemoveNodeTakesTheSubtreeUnlessAnimated) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  ok(s, at(0, AddNode{group("b", "a")}));
  ok(s, at(0, AddNode{group("c")}));
  ok(s, at(0, AddAnimation{slide("slide", "b")}));
  refused(s, at(0, RemoveNode{"a"}), "drives 'b'");
  ok(s, at(0, RemoveAnimation{"slide"}));
  s.take_changes();
  ok(s, at(0, RemoveNode{"a"}));
  EXPECT_EQ(s.nodes().size(), 1u);
  const ChangeSet c = s.take_changes();
  EXPECT_EQ(c.removed, (std::vector<NodeId>{"a", "b"}));
  EXPECT_TRUE(c.updated.empty());
}

TEST(Scene, MaterialOnlyOnModelsAndActors) {
  Scene s;
  ok(s, at(0, AddNode{group("g")}));
  Node actor = group("actor");
  actor.kind = NodeKind::actor;
  actor.actor_id = "actor0";
  ok(s, at(0, AddNode{actor}));
  Material m;
  m.high_contrast = true;
  m.colour = {1, 0, 0, 1};
  refused(s, at(0, SetMaterial{"g", m}), "no material");
  ok(s, at(0, SetMaterial{"actor", m}));
  EXPECT_TRUE(s.find("actor")->material.high_contrast);
  m.colour[1] = 2;
  refused(s, at(0, SetMaterial{"actor", m}), "colour");
}

TEST(Scene, ChangesListWhatToPublish) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  ok(s, at(0, AddNode{group("b")}));
  EXPECT_EQ(s.take_changes().updated, (std::vector<NodeId>{"a", "b"}));
  EXPECT_FALSE(s.has_changes());
  ok(s, at(1, SetVisible{"b", false}));
  EXPECT_EQ(s.take_changes().updated, (std::vector<NodeId>{"b"}));
  EXPECT_FALSE(s.effectively_visible("b"));
  refused(s, at(1, SetVisible{"q", false}), "unknown node");
  EXPECT_FALSE(s.has_changes());
}

TEST(Scene, AnimationPlaysOnTheStudioClock) {
  Scene s;  // 25 fps
  ok(s, at(0, AddNode{group("n")}));
  refused(s, at(0, AddAnimation{slide("s", "ghost")}), "unknown node");
  ok(s, at(0, AddAnimation{slide("s", "n")}));
  refused(s, at(0, AddAnimation{slide("s", "n")}), "exists");
  refused(s, at(0, Play{"nope"}), "unknown animation");
  ok(s, at(100, Play{"s"}));  // start at a future frame
  ok(s, at(50, Tick{}));
  EXPECT_EQ(s.find("n")->local.translation.x(), 0.0);
  s.take_changes();
  ok(s, at(125, Tick{}));  // 1 s later: half way
  EXPECT_NEAR(s.find("n")->local.translation.x(), 2.0, 1e-12);
  EXPECT_EQ(s.find("n")->frame, 125);
  EXPECT_EQ(s.take_changes().updated, (std::vector<NodeId>{"n"}));
  ok(s, at(125, Pause{""}));  // every animation
  ok(s, at(200, Tick{}));
  EXPECT_NEAR(s.find("n")->local.translation.x(), 2.0, 1e-12);
  EXPECT_FALSE(s.has_changes());  // paused: nothing to publish
  ok(s, at(200, Seek{"s", 0.5}));
  ok(s, at(200, SetSpeed{"s", 2.0}));
  refused(s, at(200, SetSpeed{"s", NAN}), "speed");
  ok(s, at(200, Play{"s", std::nullopt, PlayMode::ping_pong}));
  ok(s, at(225, Tick{}));  // clock 0.5 + 2 * 1 s = 2.5 -> ping-pong 1.5 -> x = 3
  EXPECT_NEAR(s.find("n")->local.translation.x(), 3.0, 1e-12);
  EXPECT_EQ(s.frame(), 225);
}

TEST(Scene, BatchIsAllOrNothing) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  const auto before = serialize(s);
  Batch bad{{at(0, AddNode{group("b")}), at(0, AddNode{group("c", "b")}),
             at(0, SetParent{"a", "c"}), at(0, SetParent{"b", "c"})}};  // the last makes a cycle
  auto r = s.apply(at(0, bad));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("command 3"), std::string::npos) << r.error().message;
  EXPECT_EQ(serialize(s), before);
  bad.commands.pop_back();
  ok(s, at(0, bad));
  EXPECT_EQ(s.nodes().size(), 3u);
  EXPECT_EQ(s.find("a")->parent, "c");
  Batch nested{{at(0, Batch{})}};
  refused(s, at(0, nested), "nested");
}

TEST(Scene, HashCoversNodesAndTheAnimationClock) {
  Scene s;
  ok(s, at(0, AddNode{group("n")}));
  ok(s, at(0, AddAnimation{slide("s", "n")}));
  const auto h0 = s.state_hash();
  Scene copy(s);
  EXPECT_EQ(copy.state_hash(), h0);
  ok(s, at(10, Seek{"s", 0.0}));  // the pose is unchanged until a Tick, the clock is not
  EXPECT_NE(s.state_hash(), h0);
  ok(copy, at(0, SetVisible{"n", false}));
  EXPECT_NE(copy.state_hash(), h0);
}

TEST(Serialize, RoundTripKeepsTheHashAndTheState) {
  Scene s(SceneOptions{1.0 / 30});
  ok(s, at(0, AddNode{group("root")}));
  Node light = group("lamp", "root", {0, 3, 0});
  light.kind = NodeKind::light;
  light.light.type = LightType::spot;
  light.light.intensity = 40;
  ok(s, at(0, AddNode{light}));
  Node m = group("m", "root");
  m.kind = NodeKind::model;
  m.asset = {"set.glb", "ab12", {0, 3}};
  m.material.texture = "canvas.png";
  ok(s, at(0, AddNode{m}));
  ok(s, at(3, AddAnimation{slide("s", "m")}));
  ok(s, at(4, Play{"s"}));
  ok(s, at(17, Tick{}));
  const auto bytes = serialize(s);
  auto back = deserialize(bytes);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->state_hash(), s.state_hash());
  EXPECT_EQ(back->nodes(), s.nodes());
  EXPECT_EQ(back->animations(), s.animations());
  EXPECT_EQ(back->options(), s.options());
  EXPECT_EQ(back->take_changes().updated.size(), 3u);  // a restored scene republishes everything
  // It keeps running like the original.
  ok(s, at(40, Tick{}));
  ok(*back, at(40, Tick{}));
  EXPECT_EQ(back->state_hash(), s.state_hash());
}

TEST(Serialize, CorruptBytesAreAnErrorNeverACrash) {
  Scene s;
  ok(s, at(0, AddNode{group("a")}));
  ok(s, at(0, AddNode{group("b", "a")}));
  ok(s, at(0, AddAnimation{slide("s", "b")}));
  const auto bytes = serialize(s);
  ASSERT_TRUE(deserialize(bytes));  // positive control
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + n);
    EXPECT_FALSE(deserialize(cut)) << "truncated at " << n;
  }
  std::size_t accepted = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    auto flipped = bytes;
    flipped[i] ^= 0xff;
    if (auto r = deserialize(flipped)) {
      ++accepted;  // some flips land in free values (a coordinate): the result must still hold
      EXPECT_TRUE(r->check_invariants());
    }
  }
  EXPECT_LT(accepted, bytes.size());
  auto trailing = bytes;
  trailing.push_back(0);
  EXPECT_FALSE(deserialize(trailing));
}

// SceneNode / SceneCommand <-> the scene library (wire/scene_convert.h) and the scene topics'
// validators (idl/src/scene_validate.cc): exact round trips of every command kind the random
// generator makes, and counted rejections of NaNs, bad enums, unterminated strings and bad
// lengths beside positive controls.
#include "wire/scene_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "scene_testing/random_commands.h"
#include "wire/sample.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

template <class E>
void poke(E& e, uint32_t v) {
  std::memcpy(&e, &v, sizeof v);
}

TEST(SceneConvert, EveryGeneratedCommandRoundTripsExactly) {
  scene::Scene scene;
  scene::testing::RandomCommandSource source(11);
  int sent = 0, exact = 0;
  for (int i = 0; i < 5000; ++i) {
    scene::Command c = source.next(scene);
    if (std::holds_alternative<scene::Batch>(c.op)) continue;  // no wire form
    if (c.frame < 0) c.frame = -5;                             // SCENE_AT_NOW is -1 on the wire
    Owned<studio_SceneCommand> s;
    ASSERT_TRUE(from_core(c, *s).has_value()) << i;
    const bool structurally_ok = !validate(*s).has_value();
    if (!structurally_ok) {
      // Whatever the validator refuses (NaN, a negative frame), the library refuses too.
      scene::Scene copy = scene;
      EXPECT_FALSE(copy.apply(c).has_value()) << i << " " << scene::command_name(c.op);
    } else {
      auto back = to_core(*s, 1234);
      ASSERT_TRUE(back.has_value()) << back.error().message;
      EXPECT_EQ(*back, c) << i << " " << scene::command_name(c.op);
      ++exact;
    }
    (void)scene.apply(c);
    ++sent;
  }
  EXPECT_GT(sent, 4000);
  EXPECT_GT(exact, 3500);
}

TEST(SceneConvert, NodesRoundTripExactly) {
  scene::Scene scene;
  scene::testing::RandomCommandSource source(12);
  for (int i = 0; i < 3000; ++i) (void)scene.apply(source.next(scene));
  ASSERT_GT(scene.nodes().size(), 50u);
  std::set<scene::NodeKind> kinds;
  for (const auto& [id, n] : scene.nodes()) {
    Owned<studio_SceneNode> s;
    ASSERT_TRUE(from_core(n, *s).has_value());
    EXPECT_FALSE(validate(*s).has_value()) << id;
    auto back = to_core(*s);
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, n) << id;
    kinds.insert(n.kind);
    // The matrix is the TRS's.
    const Eigen::Matrix4d m = n.local.matrix();
    for (int k = 0; k < 12; ++k) EXPECT_DOUBLE_EQ(s->parent_from_node[k], m(k / 4, k % 4));
  }
  EXPECT_EQ(kinds.size(), 4u);
  scene::Node too_long;
  too_long.id = std::string(64, 'x');
  Owned<studio_SceneNode> s;
  EXPECT_FALSE(from_core(too_long, *s).has_value());
}

TEST(SceneConvert, MoveNodeMatrixIsDecomposedIntoTrs) {
  scene::Transform t;
  t.translation = {1, 2, 3};
  t.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  t.scale = {2, 0.5, 1.5};
  const Eigen::Matrix4d m = t.matrix();
  Owned<studio_SceneCommand> s;
  s->verb = studio_SCENE_MOVE_NODE;
  set(s->target, "n");
  for (int k = 0; k < 16; ++k) s->transform[k] = m(k / 4, k % 4);
  ASSERT_FALSE(validate(*s).has_value());
  auto c = to_core(*s, 7);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->frame, 0);  // at_frame as sent; SCENE_AT_NOW below
  const auto& st = std::get<scene::SetTransform>(c->op);
  EXPECT_TRUE(st.local.matrix().isApprox(m, 1e-12));
  s->at_frame = studio_SCENE_AT_NOW;
  EXPECT_EQ(to_core(*s, 99)->frame, 99);
}

TEST(SceneValidate, MalformedCommandsAreRejectedWithTheirReason) {
  auto good = [] {
    Owned<studio_SceneCommand> s;
    s->verb = studio_SCENE_ADD_ANIMATION;
    set(s->target, "a");
    s->mode = studio_SCENE_MODE_LOOP;
    resize(s->tracks, 1);
    set(view(s->tracks)[0].node, "n");
    assign(view(s->tracks)[0].times, std::vector<double>{0, 1});
    assign(view(s->tracks)[0].values, std::vector<double>(8, 0.5));
    return s;
  };
  EXPECT_FALSE(validate(*good()).has_value());  // positive control

  auto s = good();
  s->node.translation[1] = NAN;
  EXPECT_EQ(validate(*s), Reject::non_finite);
  s = good();
  s->value = INFINITY;
  EXPECT_EQ(validate(*s), Reject::non_finite);
  s = good();
  poke(s->verb, 99);
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s = good();
  poke(s->mode, 4);
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s = good();
  poke(s->node.kind, 4);
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s = good();
  s->at_frame = -2;
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s = good();
  std::memset(s->sender, 'x', sizeof s->sender);  // unterminated
  EXPECT_EQ(validate(*s), Reject::bad_id);
  s = good();
  std::memset(s->node.texture, 'x', sizeof s->node.texture);
  EXPECT_EQ(validate(*s), Reject::bad_id);
  s = good();
  assign(view(s->tracks)[0].values, std::vector<double>(7, 0.5));  // not 4 per key
  EXPECT_EQ(validate(*s), Reject::bad_size);
  s = good();
  view(s->tracks)[0].path = 3;
  EXPECT_EQ(validate(*s), Reject::out_of_range);
  s = good();
  view(view(s->tracks)[0].times)[1] = NAN;
  EXPECT_EQ(validate(*s), Reject::non_finite);

  Owned<studio_SceneNode> n;
  set(n->node_id, "n");
  n->parent_from_node[15] = 1;
  EXPECT_FALSE(validate(*n).has_value());
  n->flags = 1u << 9;
  EXPECT_EQ(validate(*n), Reject::out_of_range);
  n->flags = 0;
  n->colour[2] = NAN;
  EXPECT_EQ(validate(*n), Reject::non_finite);
  n->colour[2] = 0;
  poke(n->light_type, 3);
  EXPECT_EQ(validate(*n), Reject::out_of_range);
}

}  // namespace
}  // namespace studio::wire

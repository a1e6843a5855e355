// scene.yaml: the default scene file, strict errors naming the key, build_scene.
#include <gtest/gtest.h>

#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"

using namespace studio;
using namespace studio::scene_assets;
using namespace studio::scene_config;

namespace {
const std::string kDefault = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml";

std::string error_of(const std::string& text) {
  auto d = parse_scene_text(text, "scene.yaml");
  return d ? std::string("(accepted)") : d.error().message;
}
}  // namespace

TEST(SceneYaml, DefaultSceneBuilds) {
  auto d = read_scene_file(kDefault);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->set, std::string(STUDIO_SCENE_DEFAULT_DIR) + "/museum.glb");
  ASSERT_TRUE(d->view);
  AssetCache cache;
  auto s = build_scene(*d, cache);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_TRUE(s->find("set/flyer")->material.high_contrast);
  EXPECT_EQ(s->find("actor")->kind, scene::NodeKind::actor);
  EXPECT_EQ(s->find("actor")->actor_id, "actor0");
  EXPECT_TRUE(s->animations().at("set/flight").clock.playing);
  EXPECT_TRUE(s->check_invariants());
  // Built twice, the same state.
  auto again = build_scene(*d, cache);
  EXPECT_EQ(again->state_hash(), s->state_hash());
}

TEST(SceneYaml, ExtraNodesAndAnimations) {
  auto d = parse_scene_text(R"(
nodes:
  - {id: a, translation: [1, 2, 3]}
  - {id: b, parent: a, colour: [1, 0, 0, 1], high_contrast: true, actor: act1}
animations:
  - name: bob
    mode: ping_pong
    tracks:
      - {node: a, path: translation, interpolation: step, times: [0, 1], values: [0, 0, 0, 0, 1, 0]}
play:
  - {animation: bob, at_frame: 10, speed: 2}
)", "scene.yaml");
  ASSERT_TRUE(d) << d.error().message;
  AssetCache cache;
  auto s = build_scene(*d, cache, 20);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->find("b")->parent, "a");
  EXPECT_EQ(s->animations().at("bob").animation.mode, scene::PlayMode::ping_pong);
  EXPECT_EQ(s->animations().at("bob").clock.speed, 2.0);
  // Frame 20: clock 2 * 10 * 0.04 = 0.8 s -> step key 0.
  EXPECT_EQ(s->find("a")->local.translation.y(), 0.0);
}

TEST(SceneYaml, ErrorsNameFileLineAndKey) {
  EXPECT_NE(error_of("sett: museum.glb\n").find("scene.yaml:1: sett: unknown key"), std::string::npos)
      << error_of("sett: museum.glb\n");
  EXPECT_NE(error_of("fps: fast\n").find("fps"), std::string::npos);
  EXPECT_NE(error_of("nodes:\n  - {id: a, colour: [1, 0, 0]}\n").find("nodes[0].colour"), std::string::npos)
      << error_of("nodes:\n  - {id: a, colour: [1, 0, 0]}\n");
  EXPECT_NE(error_of("nodes:\n  - {parent: x}\n").find("id: missing required key"), std::string::npos);
  EXPECT_NE(error_of("play:\n  - {animation: x, mode: sideways}\n").find("mode"), std::string::npos);
  EXPECT_NE(error_of("view: {eye: [0, 0, 0]}\n").find("at"), std::string::npos);
  EXPECT_NE(error_of("nodes: [\n").find("scene.yaml"), std::string::npos);
  for (const char* bad : {"sett: x\n", "fps: fast\n", "nodes: [\n"})
    EXPECT_EQ(error_of(bad).find('\n'), std::string::npos);
  EXPECT_EQ(error_of("fps: 30\n"), "(accepted)");  // positive control
}

TEST(SceneYaml, BuildErrorsNameTheSceneFile) {
  AssetCache cache;
  auto d = parse_scene_text("set: missing.glb\n", "/tmp/scene.yaml");
  ASSERT_TRUE(d);
  auto s = build_scene(*d, cache);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("/tmp/scene.yaml: set:"), std::string::npos) << s.error().message;
  auto orphan = parse_scene_text("nodes:\n  - {id: a, parent: ghost}\n", "scene.yaml");
  ASSERT_TRUE(orphan);
  auto o = build_scene(*orphan, cache);
  ASSERT_FALSE(o);
  EXPECT_NE(o.error().message.find("unknown parent 'ghost'"), std::string::npos) << o.error().message;
  auto bad_track = parse_scene_text(
      "animations:\n  - {name: x, tracks: [{node: a, times: [0, 1], values: [1, 2, 3]}]}\n", "s.yaml");
  ASSERT_TRUE(bad_track);
  EXPECT_FALSE(build_scene(*bad_track, cache));
}

// studioctl scene as a process against a real studio-scene (the demo museum scene made at build
// time, persisted in the test's folder) over Cyclone DDS on loopback:
//  - hash: the server's state and the nodes hash studioctl computes from the studio/scene/node
//    instances it receives agree; negative control: a rogue writer adding a node the server does
//    not hold makes them differ (exit 1), and they agree again once it is gone;
//  - pause freezes the nodes (the same nodes hash twice, 0.5 s apart), play moves them again;
//    seek to a time gives the same nodes whenever it is sent (seek 1, seek 2, seek 1: first and
//    last agree, the middle differs); speed is accepted; every verdict names the new state;
//  - load replaces the scene (one node fewer from a scene file without the actor); a missing
//    file and an unknown animation are rejected by the server with its error (exit 1);
//  - bad usage is one line, exit 2; --help documents every verb.
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "harness/fixture.h"
#include "studioctl/testing/run.h"
#include "wire/endpoint.h"

namespace studio::ctl {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using ctl::testing::Json;

const fs::path kScene = STUDIO_SCENE_DEFAULT_DIR;

class SceneVerbsTest : public studio::testing::ProcessTest {
 protected:
  ctl::testing::Run studioctl(const std::vector<std::string>& args) {
    return ctl::testing::run_studioctl(args,
                                       dir_ / ("studioctl." + std::to_string(runs_++) + ".err"));
  }
  std::string write_file(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  studio::testing::Process& start_scene() {
    const std::string config =
        write_file("scene.yaml", "instance: scene0\nstatus_period: 0.5\nclock: {fps: 25}\nscene: " +
                                     (kScene / "scene.yaml").string() +
                                     "\nstate_dir: " + (dir_ / "state").string() + "\n");
    auto& p = spawn("scene", "scene/studio-scene", {"--config", config});
    EXPECT_TRUE(p.wait_ready(30s)) << p.log();
    return p;
  }
  // `scene hash --json`, which must succeed; its one object.
  Json hash() {
    auto r = studioctl({"scene", "hash", "--json", "--wait", "20"});
    EXPECT_EQ(r.code, 0) << r.err << r.out;
    auto j = ctl::testing::json_lines_of(r.out);
    EXPECT_EQ(j.size(), 1u) << r.out;
    return j.empty() ? Json{} : j[0];
  }
  // The published translation and rotation of the animated node set/flyer, as text.
  std::string flyer_pose() {
    auto r = studioctl({"topic", "echo", "studio/scene/node", "--key", "set/flyer", "--json",
                        "--count", "1", "--timeout", "10"});
    EXPECT_EQ(r.code, 0) << r.err;
    auto j = ctl::testing::json_lines_of(r.out);
    if (j.empty()) return "";
    std::string pose;
    for (const char* k : {"translation", "rotation"})
      for (const auto& v : j[0].find(k)->array) pose += std::to_string(v.number) + " ";
    return pose;
  }
  std::string field(const Json& j, const char* key) {
    const Json* v = j.find(key);
    return v ? v->string : "";
  }
  int runs_ = 0;
};

TEST_F(SceneVerbsTest, HashAgreesWithTheNodesReceivedAndARogueNodeIsNoticed) {
  start_scene();
  const Json h = hash();
  EXPECT_TRUE(h.find("consistent")->boolean);
  EXPECT_EQ(field(h, "instance"), "scene0");
  EXPECT_GT(h.find("node_count")->number, 3) << "the museum scene";
  EXPECT_GE(h.find("animation_count")->number, 1);
  EXPECT_EQ(field(h, "nodes_hash"), field(h, "local_nodes_hash"));
  EXPECT_EQ(field(h, "state_hash").size(), 16u);
  auto text = studioctl({"scene", "hash"});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("consistent"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("state_hash "), std::string::npos) << text.out;

  // A writer the server does not know adds a node: this host's scene differs from the server's.
  {
    auto p = wire::Participant::create().value();
    auto t = wire::Topic<studio_SceneNode>::create(p).value();
    auto w = wire::Writer<studio_SceneNode>::create(p, t).value();
    wire::Owned<studio_SceneNode> n;
    wire::set(n->node_id, "rogue");
    n->kind = studio_SCENE_KIND_GROUP;
    n->rotation[3] = 1;
    n->scale[0] = n->scale[1] = n->scale[2] = 1;
    for (int i = 0; i < 4; ++i) n->parent_from_node[5 * i] = 1;
    n->flags = studio_SCENE_NODE_VISIBLE;
    ASSERT_TRUE(w.write(*n).has_value());
    auto r = studioctl({"scene", "hash", "--wait", "3"});
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("DIFFERENT"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("differ from the server's"), std::string::npos) << r.err;
    ASSERT_TRUE(w.dispose(*n).has_value());
  }
  EXPECT_TRUE(hash().find("consistent")->boolean);
}

TEST_F(SceneVerbsTest, PausePlaySeekAndSpeedChangeTheSceneAsTheServerConfirms) {
  start_scene();
  auto pause = studioctl({"scene", "pause", "--json"});
  ASSERT_EQ(pause.code, 0) << pause.err;
  auto v = ctl::testing::json_lines_of(pause.out);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_TRUE(v[0].find("accepted")->boolean);
  EXPECT_EQ(field(v[0], "instance"), "scene0");
  const std::string paused = field(hash(), "nodes_hash");
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(field(hash(), "nodes_hash"), paused) << "paused: the flyer must not move";

  auto play = studioctl({"scene", "play", "--mode", "loop"});
  ASSERT_EQ(play.code, 0) << play.err;
  EXPECT_NE(play.out.find("play: accepted"), std::string::npos) << play.out;
  std::this_thread::sleep_for(500ms);
  EXPECT_NE(field(hash(), "nodes_hash"), paused) << "playing: the flyer moves";

  // Seek: the flyer's pose is a function of the animation time (the nodes hash also holds the
  // frame each transform was set at, so the pose itself is compared).
  ASSERT_EQ(studioctl({"scene", "pause"}).code, 0);
  // (the clock moves at once; the nodes at the next tick, one frame later)
  ASSERT_EQ(studioctl({"scene", "seek", "1.0"}).code, 0);
  std::this_thread::sleep_for(300ms);
  const std::string at1 = flyer_pose();
  ASSERT_EQ(studioctl({"scene", "seek", "2.0", "--animation", "set/flight"}).code, 0);
  std::this_thread::sleep_for(300ms);
  const std::string at2 = flyer_pose();
  ASSERT_EQ(studioctl({"scene", "seek", "1.0"}).code, 0);
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(at1.empty());
  EXPECT_NE(at1, at2);
  EXPECT_EQ(flyer_pose(), at1) << "seek is a position, not a delta";

  auto speed = studioctl({"scene", "speed", "-0.5", "--json"});
  ASSERT_EQ(speed.code, 0) << speed.err;
  EXPECT_TRUE(ctl::testing::json_lines_of(speed.out).at(0).find("accepted")->boolean);

  // Rejections by the server, with its error.
  auto unknown = studioctl({"scene", "play", "--animation", "no/such"});
  EXPECT_EQ(unknown.code, 1);
  EXPECT_NE(unknown.err.find("rejected by the scene server"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("no/such"), std::string::npos) << unknown.err;
}

TEST_F(SceneVerbsTest, LoadReplacesTheSceneAndAMissingFileIsRejected) {
  start_scene();
  const double before = hash().find("node_count")->number;
  // The museum without its actor node.
  const std::string file = write_file(
      "no_actor.yaml", "set: " + (kScene / "museum.glb").string() +
                           "\nset_id: set\nfps: 25\nplay:\n  - {animation: set/flight, at_frame: "
                           "0, mode: loop}\n");
  auto load = studioctl({"scene", "load", file, "--json"});
  ASSERT_EQ(load.code, 0) << load.err << load.out;
  auto v = ctl::testing::json_lines_of(load.out);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].find("node_count")->number, before - 1) << load.out;
  const Json after = hash();
  EXPECT_EQ(after.find("node_count")->number, before - 1);
  EXPECT_TRUE(after.find("consistent")->boolean);

  auto missing = studioctl({"scene", "load", (dir_ / "absent.yaml").string()});
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("rejected by the scene server: load_set"), std::string::npos)
      << missing.err;
  EXPECT_NE(missing.err.find("absent.yaml"), std::string::npos) << missing.err;
  EXPECT_EQ(hash().find("node_count")->number, before - 1) << "all or nothing";
}

TEST_F(SceneVerbsTest, HelpAndBadUsage) {
  for (std::vector<std::string> args : {std::vector<std::string>{"scene", "--help"},
                                        {"scene", "hash", "--help"},
                                        {"scene", "load", "--help"},
                                        {"scene", "play", "--help"}}) {
    auto r = studioctl(args);
    EXPECT_EQ(r.code, 0);
    for (const char* verb : {"load FILE", "play", "pause", "seek SECONDS", "speed FACTOR", "hash"})
      EXPECT_NE(r.out.find(verb), std::string::npos) << verb;
    EXPECT_NE(r.out.find("--json"), std::string::npos);
  }
  struct Bad {
    std::vector<std::string> args;
    std::string expect;
  } bad[] = {
      {{"scene", "rewind"}, "unknown verb 'rewind'"},
      {{"scene", "seek"}, "expected one SECONDS"},
      {{"scene", "speed", "fast"}, "FACTOR: expected a number"},
      {{"scene", "play", "--mode", "sideways"}, "--mode: expected once, loop or ping-pong"},
      {{"scene", "pause", "--from", "1"}, "--from and --mode are play's options"},
      {{"scene", "hash", "extra"}, "unexpected argument 'extra'"},
  };
  for (const auto& b : bad) {
    auto r = studioctl(b.args);
    EXPECT_EQ(r.code, 2) << b.args[1];
    EXPECT_NE(r.err.find(b.expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // No server: a clear failure, not a hang.
  auto none = studioctl({"scene", "pause", "--wait", "1"});
  EXPECT_EQ(none.code, 1);
  EXPECT_NE(none.err.find("no scene server is listening"), std::string::npos) << none.err;
  auto nohash = studioctl({"scene", "hash", "--wait", "1"});
  EXPECT_EQ(nohash.code, 1);
  EXPECT_NE(nohash.err.find("no scene server reported its state"), std::string::npos) << nohash.err;
}

}  // namespace
}  // namespace studio::ctl

// The scene server as a real process (issue 14, Done-when): studio-scene is spawned, commands go
// over real Cyclone DDS on loopback, and reader participants rebuild the scene from the keyed
// studio/scene/node instances.
//   - a reader that joins late gets the complete scene (600 nodes) within 100 ms of matching;
//   - a burst of 10 000 random commands (valid and invalid mixed) leaves the server's state hash
//     equal to an independent replay of the same log through the library, two readers holding
//     exactly the replay's nodes, and every invalid command rejected and counted;
//   - kill -9 and restart: readers converge to the persisted state, no removed node comes back,
//     and a node taken out of the state while the server was down is disposed;
//   - bad commands (unknown node, NaN transform, cycle, ...) rejected by reason, the server keeps
//     running, a valid command still applies;
//   - the configured scene (the default museum scene made at build time) is what the readers get,
//     SCENE_LOAD_SET replaces it all or nothing, a missing set file is a counted rejection;
//   - bad configuration and a corrupt state file: one line, exit 1; --help lists the keys.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <thread>

#include "harness/fixture.h"
#include "scene/scene.h"
#include "scene_loading.h"
#include "scene_testing/random_commands.h"
#include "state_file.h"
#include "wire/endpoint.h"
#include "wire/scene_convert.h"

namespace studio::scene {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

// One reader participant: the alive SceneNode instances as scene::Nodes (a disposed instance
// is erased; a writer that vanished without disposing leaves its nodes, so stale nodes show).
// Written as every reader of studio/scene/node must read it: keyed by node_id, a sample of a
// disposed instance (with or without data) removes the node.
struct Mirror {
  wire::Participant participant = wire::Participant::create().value();
  wire::Topic<studio_SceneNode> topic = wire::Topic<studio_SceneNode>::create(participant).value();
  wire::Reader<studio_SceneNode> reader =
      wire::Reader<studio_SceneNode>::create(participant, topic).value();
  std::map<NodeId, Node> nodes;
  std::size_t samples = 0;

  // Takes what arrived; returns the number of samples with data.
  std::size_t poll() {
    std::size_t n = 0;
    for (;;) {
      auto got = reader.take(256);
      if (got.empty()) return n;
      for (auto& r : got) {
        // A node written and then disposed before this reader took it arrives as its last
        // data with the instance disposed: that is a removal too.
        if (r.meta.disposed) {
          nodes.erase(r.data->node_id);
        } else if (r.meta.valid_data) {
          auto node = wire::to_core(*r.data);
          EXPECT_TRUE(node.has_value());
          if (node) nodes[node->id] = std::move(*node);
        }
        if (r.meta.valid_data) {
          ++n;
          ++samples;
        }
      }
    }
  }
  // Polls until pred() holds or the timeout passes.
  template <class Pred>
  bool until(Pred pred, std::chrono::milliseconds timeout) {
    const auto deadline = SteadyClock::now() + timeout;
    do {
      poll();
      if (pred()) return true;
      std::this_thread::sleep_for(2ms);
    } while (SteadyClock::now() < deadline);
    poll();
    return pred();
  }
};

class SceneServerTest : public studio::testing::ProcessTest {
 protected:
  void SetUp() override {
    ProcessTest::SetUp();
    participant_.emplace(wire::Participant::create().value());
    cmd_topic_.emplace(wire::Topic<studio_SceneCommand>::create(*participant_).value());
    state_topic_.emplace(wire::Topic<studio_SceneState>::create(*participant_).value());
    status_topic_.emplace(wire::Topic<studio_ServiceStatus>::create(*participant_).value());
    // The command writer keeps all history, so a burst far over the topic's keep-last 32 is
    // flow-controlled by the server's acknowledgements instead of overwriting unacknowledged
    // samples (the server's reader keeps command_queue samples).
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    writer_ = dds_create_writer(participant_->handle(), cmd_topic_->handle(), qos, nullptr);
    dds_delete_qos(qos);
    ASSERT_GT(writer_, 0) << dds_strretcode(writer_);
    state_.emplace(wire::Reader<studio_SceneState>::create(*participant_, *state_topic_).value());
    status_.emplace(
        wire::Reader<studio_ServiceStatus>::create(*participant_, *status_topic_).value());
  }
  void TearDown() override {
    status_.reset();
    state_.reset();
    if (writer_ > 0) dds_delete(writer_);
    status_topic_.reset();
    state_topic_.reset();
    cmd_topic_.reset();
    participant_.reset();
    ProcessTest::TearDown();
  }

  std::string write_config(const std::string& text, const std::string& name = "scene.yaml") {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  studio::testing::Process& start_server(const std::string& yaml,
                                         const std::string& name = "scene") {
    auto& p = spawn(name, "scene/studio-scene", {"--config", write_config(yaml)});
    EXPECT_TRUE(p.wait_ready(20s)) << p.log();
    dds_publication_matched_status_t m{};
    for (auto deadline = SteadyClock::now() + 10s; SteadyClock::now() < deadline;
         std::this_thread::sleep_for(5ms))
      if (dds_get_publication_matched_status(writer_, &m) == DDS_RETCODE_OK && m.current_count > 0)
        break;
    EXPECT_GT(m.current_count, 0u) << "the server's command reader did not match";
    return p;
  }

  // Sends one command (sender "test", increasing command_id).
  void send(const Command& c) {
    wire::Owned<studio_SceneCommand> s;
    ASSERT_TRUE(wire::from_core(c, *s).has_value());
    send(*s);
  }
  void send(studio_SceneCommand& s) {
    wire::set(s.sender, "test");
    s.command_id = ++command_id_;
    s.capture_ns = realtime_ns();
    ASSERT_EQ(dds_write(writer_, &s), DDS_RETCODE_OK);
  }
  void wait_acks() { ASSERT_EQ(dds_wait_for_acks(writer_, DDS_SECS(20)), DDS_RETCODE_OK); }

  static int64_t realtime_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }

  // The newest SceneState once pred(state) holds (or the last one seen at the timeout).
  template <class Pred>
  std::optional<wire::Owned<studio_SceneState>> state_when(Pred pred,
                                                           std::chrono::seconds timeout) {
    std::optional<wire::Owned<studio_SceneState>> last;
    const auto deadline = SteadyClock::now() + timeout;
    while (SteadyClock::now() < deadline) {
      for (auto& r : state_->take())
        if (r.meta.valid_data) last.emplace(std::move(r.data));
      if (last && pred(**last)) return last;
      std::this_thread::sleep_for(5ms);
    }
    return last;
  }

  // Counters of the server's newest ServiceStatus once pred(counters) holds.
  template <class Pred>
  std::map<std::string, double> counters_when(Pred pred, std::chrono::seconds timeout) {
    std::map<std::string, double> counters;
    const auto deadline = SteadyClock::now() + timeout;
    while (SteadyClock::now() < deadline) {
      for (auto& r : status_->take()) {
        if (!r.meta.valid_data || std::string(r.data->service) != "scene") continue;
        for (const auto& c : wire::view(r.data->counters)) counters[c.name] = c.value;
      }
      if (pred(counters)) return counters;
      std::this_thread::sleep_for(20ms);
    }
    return counters;
  }

  static Node model(const std::string& id, const std::string& parent, double x) {
    Node n;
    n.id = id;
    n.parent = parent;
    n.kind = NodeKind::model;
    n.asset = {"sets/hall.glb", std::string(64, 'a'), {0, 2}};
    n.material.colour = {0.8f, 0.2f, 0.1f, 1.0f};
    n.material.high_contrast = x > 1;
    n.local.translation = {x, 0.5, -x};
    return n;
  }

  std::optional<wire::Participant> participant_;
  std::optional<wire::Topic<studio_SceneCommand>> cmd_topic_;
  std::optional<wire::Topic<studio_SceneState>> state_topic_;
  std::optional<wire::Topic<studio_ServiceStatus>> status_topic_;
  dds_entity_t writer_ = 0;
  std::optional<wire::Reader<studio_SceneState>> state_;
  std::optional<wire::Reader<studio_ServiceStatus>> status_;
  uint64_t command_id_ = 0;
};

TEST_F(SceneServerTest, LateReaderGetsTheWholeSceneWithin100msOfMatching) {
  start_server("instance: s1\nclock: {source: commands}\n");
  Scene expected;
  constexpr int kNodes = 600;
  for (int i = 0; i < kNodes; ++i) {
    // A forest: every 10th node a root, the others children of the root before them.
    const std::string parent = i % 10 ? "n" + std::to_string(i - i % 10) : "";
    Command c{i / 50, AddNode{model("n" + std::to_string(i), parent, 0.01 * i)}};
    ASSERT_TRUE(expected.apply(c).has_value());
    send(c);
  }
  wait_acks();
  auto st = state_when([](const studio_SceneState& s) { return s.node_count == kNodes; }, 30s);
  ASSERT_TRUE(st.has_value());
  ASSERT_EQ((*st)->node_count, uint32_t(kNodes));
  EXPECT_EQ((*st)->state_hash, expected.state_hash());

  // The late reader: time from its subscription matching the server's writer to the last node.
  Mirror late;
  std::optional<SteadyClock::time_point> matched, last;
  const auto deadline = SteadyClock::now() + 20s;
  while (late.nodes.size() < std::size_t(kNodes) && SteadyClock::now() < deadline) {
    if (!matched) {
      dds_subscription_matched_status_t m{};
      if (dds_get_subscription_matched_status(late.reader.handle(), &m) == DDS_RETCODE_OK &&
          m.current_count > 0)
        matched = SteadyClock::now();
    }
    if (late.poll() > 0) {
      last = SteadyClock::now();
      if (!matched) matched = last;  // data before the poll saw the match: start there
    } else {
      std::this_thread::sleep_for(100us);
    }
  }
  ASSERT_EQ(late.nodes.size(), std::size_t(kNodes));
  ASSERT_TRUE(matched && last);
  const double ms = std::chrono::duration<double, std::milli>(*last - *matched).count();
  std::printf("late reader: %d nodes %.1f ms after matching\n", kNodes, ms);
  EXPECT_LE(ms, 100.0);
  EXPECT_EQ(late.nodes, expected.nodes());
}

TEST_F(SceneServerTest, BurstOf10000RandomCommandsMatchesAnIndependentReplay) {
  start_server("instance: s1\nstatus_period: 0.2\nclock: {source: commands}\nstate_dir: state\n");
  Mirror a, b;
  ASSERT_TRUE(a.until([&] { return a.reader.matched_writers() > 0; }, 10s));
  ASSERT_TRUE(b.until([&] { return b.reader.matched_writers() > 0; }, 10s));

  // The command log: 10 000 random commands, valid and invalid (unknown nodes, NaN and zero
  // transforms, cycles, bad colours, unknown animations, negative frames, ...). Batches have no
  // wire form and are left out. Drawn against a scene that follows the log, so most commands
  // refer to what exists.
  std::vector<Command> log;
  {
    Scene drawing;
    testing::RandomCommandSource source(2026);
    while (log.size() < 10000) {
      Command c = source.next(drawing);
      if (std::holds_alternative<Batch>(c.op)) continue;
      if (c.frame < 0) c.frame = -7;  // -1 is SCENE_AT_NOW on the wire
      (void)drawing.apply(c);
      log.push_back(std::move(c));
    }
  }
  // The independent replay: the library alone.
  Scene replayed;
  const ReplayResult expected = replay(replayed, log);
  ASSERT_GT(expected.applied, 3000u);
  ASSERT_GT(expected.rejected, 1000u);
  ASSERT_GT(replayed.nodes().size(), 50u);

  const auto t0 = SteadyClock::now();
  for (const Command& c : log) send(c);
  wait_acks();
  const auto t1 = SteadyClock::now();

  auto st = state_when(
      [](const studio_SceneState& s) { return s.commands_accepted + s.commands_rejected >= 10000; },
      40s);
  ASSERT_TRUE(st.has_value());
  std::printf("burst: 10000 commands sent in %.2f s, all handled after %.2f s\n",
              std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(SteadyClock::now() - t0).count());
  EXPECT_EQ((*st)->commands_accepted, expected.applied);
  EXPECT_EQ((*st)->commands_rejected, expected.rejected);
  EXPECT_EQ((*st)->commands_lost, 0u);
  EXPECT_EQ((*st)->node_count, replayed.nodes().size());
  EXPECT_EQ((*st)->animation_count, replayed.animations().size());
  EXPECT_EQ((*st)->state_hash, replayed.state_hash()) << "server and replay disagree";

  // Both readers hold exactly the replay's nodes (every field, the transform's frame included).
  EXPECT_TRUE(a.until([&] { return a.nodes == replayed.nodes(); }, 10s))
      << a.nodes.size() << " vs " << replayed.nodes().size();
  EXPECT_TRUE(b.until([&] { return b.nodes == replayed.nodes(); }, 10s));
  EXPECT_EQ(a.nodes, b.nodes);

  // Rejections by reason in the status: the validator's (NaN, negative frame) and the library's.
  auto counters = counters_when(
      [&](const auto& c) {
        return c.contains("rejected") && c.at("rejected") == expected.rejected;
      },
      10s);
  EXPECT_EQ(counters["rejected"], double(expected.rejected));
  EXPECT_EQ(counters["commands_accepted"], double(expected.applied));
  EXPECT_GT(counters["rejected_malformed"], 0);
  EXPECT_GT(counters["rejected_set_parent"], 0);
  EXPECT_GT(counters["rejected_add_node"], 0);
  double by_reason = 0;
  for (const auto& [name, value] : counters)
    if (name.starts_with("rejected_") && !name.ends_with("_hz")) by_reason += value;
  EXPECT_EQ(by_reason, double(expected.rejected));

  // The persisted state is the replay's too.
  auto persisted = node::read_state((dir_ / "state").string());
  ASSERT_TRUE(persisted.has_value() && persisted->has_value());
  EXPECT_EQ((*persisted)->state.scene.state_hash(), replayed.state_hash());
  // And the durable copy (fsync'd by the server's syncer thread) catches up with it.
  bool durable = false;
  for (auto deadline = SteadyClock::now() + 10s; !durable && SteadyClock::now() < deadline;
       std::this_thread::sleep_for(20ms)) {
    std::ifstream in(node::state_path((dir_ / "state").string()), std::ios::binary);
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    auto d = node::decode_state(bytes);
    durable = d && d->scene.state_hash() == replayed.state_hash();
  }
  EXPECT_TRUE(durable);
}

TEST_F(SceneServerTest, Kill9AndRestartConvergesToThePersistedStateWithoutStaleNodes) {
  const std::string config =
      "instance: s1\nstatus_period: 0.2\nclock: {fps: 25}\nstate_dir: state\n"
      "persist_interval: 0.2\n";
  auto& first = start_server(config);
  Mirror reader;
  for (const char* id : {"a", "b", "c", "d", "spin"}) send(Command{0, AddNode{model(id, "", 1)}});
  send(Command{0, AddNode{model("a/child", "a", 2)}});
  Animation spin;
  spin.name = "spin";
  spin.mode = PlayMode::loop;
  Track t;
  t.node = "spin";
  t.path = TrackPath::translation;
  t.times = {0, 1};
  t.values = {Eigen::Vector4d(0, 0, 0, 0), Eigen::Vector4d(2, 0, 0, 0)};
  spin.tracks = {t};
  send(Command{0, AddAnimation{spin}});
  wire::Owned<studio_SceneCommand> play;
  play->verb = studio_SCENE_PLAY;
  wire::set(play->target, "spin");
  play->at_frame = studio_SCENE_AT_NOW;
  send(*play);
  send(Command{0, RemoveNode{"b"}});  // removed before the kill: must not come back
  wait_acks();
  auto st = state_when([](const studio_SceneState& s) { return s.commands_accepted == 9; }, 20s);
  ASSERT_TRUE(st && (*st)->commands_accepted == 9) << first.log();
  ASSERT_TRUE(
      reader.until([&] { return reader.nodes.size() == 5 && !reader.nodes.contains("b"); }, 10s));
  // The animation plays: the spinning node moves frame after frame.
  const int64_t f0 = reader.nodes.at("spin").frame;
  ASSERT_TRUE(reader.until([&] { return reader.nodes.at("spin").frame > f0 + 3; }, 5s));

  ASSERT_EQ(::kill(first.pid(), SIGKILL), 0);
  ASSERT_TRUE(first.wait_exit(10s).has_value());

  // While it is down, the state loses node "c" (an operator's restore, say): the persisted
  // state still lists "c" as published, so the restarted server must dispose it.
  const std::string state_dir = (dir_ / "state").string();
  auto persisted = node::read_state(state_dir);
  ASSERT_TRUE(persisted.has_value() && persisted->has_value()) << persisted.error().message;
  node::PersistedState s = std::move((*persisted)->state);
  EXPECT_FALSE(s.scene.find("b"));
  ASSERT_TRUE(s.scene.find("c"));
  EXPECT_TRUE(s.published.contains("c"));
  ASSERT_TRUE(s.scene.apply(Command{s.scene.frame(), RemoveNode{"c"}}).has_value());
  // Written as the durable copy with a higher sequence: it wins over the server's write-ahead.
  ASSERT_TRUE(node::write_state(state_dir, s.scene, s.published, s.sequence + 1).has_value());
  const int64_t persisted_frame = s.scene.frame();
  ASSERT_GT(persisted_frame, 0);  // the clock ticked and was persisted

  start_server(config, "scene-restarted");
  std::set<NodeId> want;
  for (const auto& [id, n] : s.scene.nodes()) want.insert(id);
  auto ids = [&] {
    std::set<NodeId> have;
    for (const auto& [id, n] : reader.nodes) have.insert(id);
    return have;
  };
  ASSERT_TRUE(reader.until([&] { return ids() == want; }, 15s))
      << "reader holds " << reader.nodes.size() << " nodes";
  EXPECT_FALSE(reader.nodes.contains("b"));
  EXPECT_FALSE(reader.nodes.contains("c"));
  for (const auto& [id, n] : s.scene.nodes()) {
    if (id != "spin") {
      EXPECT_EQ(reader.nodes.at(id), n) << id;
    }
  }
  // The animation resumed on the studio clock.
  ASSERT_TRUE(
      reader.until([&] { return reader.nodes.at("spin").frame > persisted_frame + 3; }, 5s));
  // Nothing stale arrives later either.
  std::this_thread::sleep_for(300ms);
  reader.poll();
  EXPECT_EQ(ids(), want);
  auto after = state_when([](const studio_SceneState& x) { return x.node_count == 4; }, 10s);
  ASSERT_TRUE(after.has_value());
  EXPECT_EQ((*after)->node_count, 4u);
  EXPECT_EQ((*after)->animation_count, 1u);
}

TEST_F(SceneServerTest, BadCommandsAreRejectedByReasonAndTheServerCarriesOn) {
  auto& server = start_server("instance: s1\nstatus_period: 0.2\nclock: {source: commands}\n");
  Mirror reader;
  send(Command{0, AddNode{model("a", "", 0)}});
  send(Command{0, AddNode{model("b", "a", 1)}});
  ASSERT_TRUE(reader.until([&] { return reader.nodes.size() == 2; }, 10s));

  Transform moved;
  moved.translation = {3, 2, 1};
  send(Command{1, SetTransform{"ghost", moved}});  // unknown node
  Transform nan = moved;
  nan.translation.y() = std::nan("");
  send(Command{1, SetTransform{"a", nan}});  // NaN: the validator
  send(Command{1, SetParent{"a", "b"}});     // cycle
  wire::Owned<studio_SceneCommand> load;
  load->verb = studio_SCENE_LOAD_SET;
  wire::set(load->path, "sets/hall.yaml");
  send(*load);
  wire::Owned<studio_SceneCommand> keep;  // an animation without a mode
  keep->verb = studio_SCENE_ADD_ANIMATION;
  wire::set(keep->target, "x");
  send(*keep);
  auto cycle =
      state_when([&](const studio_SceneState& s) { return s.commands_rejected == 5; }, 10s);
  ASSERT_TRUE(cycle.has_value());
  EXPECT_EQ((*cycle)->commands_rejected, 5u);
  EXPECT_EQ((*cycle)->commands_accepted, 2u);
  EXPECT_FALSE((*cycle)->last_accepted);
  EXPECT_NE(std::string((*cycle)->last_error).find("convert: add_animation"), std::string::npos)
      << (*cycle)->last_error;

  auto counters = counters_when(
      [](const auto& c) { return c.contains("rejected") && c.at("rejected") == 5; }, 10s);
  EXPECT_EQ(counters["rejected"], 5);
  EXPECT_EQ(counters["rejected_set_transform"], 1);  // ghost
  EXPECT_EQ(counters["rejected_malformed"], 1);      // NaN
  EXPECT_EQ(counters["rejected_set_parent"], 1);     // cycle
  EXPECT_EQ(counters["rejected_load_set"], 1);
  EXPECT_EQ(counters["rejected_convert"], 1);

  // Positive control: a valid move applies and reaches the reader; nothing half-applied before.
  EXPECT_EQ(reader.nodes.at("a").local.translation, model("a", "", 0).local.translation);
  EXPECT_EQ(reader.nodes.at("a").parent, "");
  send(Command{2, SetTransform{"a", moved}});
  ASSERT_TRUE(reader.until(
      [&] { return reader.nodes.at("a").local.translation == moved.translation; }, 10s));
  EXPECT_EQ(reader.nodes.at("a").frame, 2);
  EXPECT_TRUE(server.running());
  auto ok = state_when([](const studio_SceneState& s) { return s.commands_accepted == 3; }, 10s);
  ASSERT_TRUE(ok.has_value());
  EXPECT_TRUE((*ok)->last_accepted);
}

TEST_F(SceneServerTest, ConfiguredSceneThenLoadSetReplacesItAllOrNothing) {
  const std::string museum = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/scene.yaml";
  scene_assets::AssetCache cache;
  auto expected = node::load_scene_file(museum, SceneOptions{0.04}, 0, cache);
  ASSERT_TRUE(expected.has_value()) << expected.error().message;
  ASSERT_GT(expected->nodes().size(), 10u);
  start_server("instance: s1\nstatus_period: 0.2\nclock: {source: commands}\nscene: " + museum +
               "\n");
  Mirror reader;
  ASSERT_TRUE(reader.until([&] { return reader.nodes == expected->nodes(); }, 20s))
      << reader.nodes.size() << " of " << expected->nodes().size() << " nodes";
  auto st = state_when([](const studio_SceneState&) { return true; }, 10s);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ((*st)->state_hash, expected->state_hash());
  // Models carry their asset's content hash; the flyer is drawn high-contrast.
  int hashed = 0;
  for (const auto& [id, n] : reader.nodes)
    if (n.kind == NodeKind::model) hashed += n.asset.sha256.size() == 64;
  EXPECT_GT(hashed, 5);
  ASSERT_TRUE(reader.nodes.contains("set/flyer"));
  EXPECT_TRUE(reader.nodes.at("set/flyer").material.high_contrast);

  // A missing set: rejected and counted, the scene unchanged.
  wire::Owned<studio_SceneCommand> load;
  load->verb = studio_SCENE_LOAD_SET;
  wire::set(load->path, "missing.glb");
  load->at_frame = 5;
  send(*load);
  auto bad = state_when([](const studio_SceneState& x) { return x.commands_rejected == 1; }, 10s);
  ASSERT_TRUE(bad.has_value());
  EXPECT_NE(std::string((*bad)->last_error).find("missing.glb"), std::string::npos)
      << (*bad)->last_error;
  EXPECT_EQ((*bad)->state_hash, expected->state_hash());
  auto counters = counters_when([](const auto& c) { return c.contains("rejected_load_set"); }, 10s);
  EXPECT_EQ(counters["rejected_load_set"], 1);

  // A small scene file (relative to the config's folder) replaces the whole museum.
  std::ofstream(dir_ / "small.yaml")
      << "fps: 25\nnodes:\n  - {id: marker, translation: [1, 0, 0]}\n"
         "  - {id: actor, actor: actor0}\n";
  auto small = node::load_scene_file((dir_ / "small.yaml").string(), SceneOptions{0.04}, 5, cache);
  ASSERT_TRUE(small.has_value()) << small.error().message;
  wire::set(load->path, "small.yaml");
  send(*load);
  ASSERT_TRUE(reader.until([&] { return reader.nodes == small->nodes(); }, 10s))
      << reader.nodes.size() << " nodes";
  auto ok = state_when([](const studio_SceneState& x) { return x.commands_accepted == 1; }, 10s);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ((*ok)->state_hash, small->state_hash());
}

TEST_F(SceneServerTest, BadConfigOrCorruptStateIsOneLineAndExitOne) {
  std::filesystem::create_directories(dir_ / "corrupt");
  std::ofstream(dir_ / "corrupt" / "scene.state") << "STSRVST2 but nothing else";
  struct Case {
    std::string yaml, expect;
  } cases[] = {
      {"bogus: 1\n", "scene.yaml:1: bogus: unknown key"},
      {"clock: {fps: 0}\n", "fps in 0.1..1000"},
      {"clock: {fps: 25, period_ns: 40000000}\n", "give fps or period_ns, not both"},
      {"clock: {source: wallclock}\n", "expected studio or commands"},
      {"persist_interval: 0\n", "persist_interval"},
      {"command_queue: 4\n", "command_queue"},
      {"state_dir: corrupt\n", "scene.state: corrupt state file"},
      {"scene: nowhere.glb\n", "nowhere.glb: no such set file"},
  };
  for (const auto& c : cases) {
    auto& p = spawn("scene", "scene/studio-scene", {"--config", write_config(c.yaml)});
    const auto rc = p.wait_exit(10s);
    ASSERT_TRUE(rc.has_value()) << c.yaml;
    EXPECT_EQ(*rc, 1) << c.yaml;
    const std::string log = p.log();
    EXPECT_NE(log.find(c.expect), std::string::npos) << c.yaml << " -> " << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
  auto& help = spawn("scene", "scene/studio-scene", {"--help"});
  EXPECT_EQ(help.wait_exit(10s), 0);
  for (const char* key : {"render", "clock", "fps", "period_ns", "epoch_ns", "source", "scene:",
                          "state_dir", "persist_interval", "command_queue", "studio/scene/node"})
    EXPECT_NE(help.log().find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace studio::scene

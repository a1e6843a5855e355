// The scene server's state file (state_file.h): round trip, atomic replace, and corrupt or
// truncated files refused with an error naming the file (never a crash, never a half scene).
#include "state_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "runtime/service.h"
#include "scene_config.h"
#include "scene_testing/random_commands.h"
#include "yaml_io/node.h"

namespace studio::scene::node {
namespace {

namespace fs = std::filesystem;

Scene random_scene(std::uint64_t seed, int commands) {
  Scene scene;
  testing::RandomCommandSource source(seed);
  for (int i = 0; i < commands; ++i) (void)scene.apply(source.next(scene));
  (void)scene.take_changes();
  return scene;
}

fs::path scratch_dir(const std::string& name) {
  fs::path dir =
      fs::temp_directory_path() / ("scene_state_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

TEST(StateFile, RoundTripKeepsSceneHashAndPublishedIds) {
  const Scene scene = random_scene(7, 2000);
  ASSERT_GT(scene.nodes().size(), 20u);
  std::set<NodeId> published;
  for (const auto& [id, n] : scene.nodes()) published.insert(id);
  published.insert("removed-but-not-disposed");
  const fs::path dir = scratch_dir("roundtrip");
  ASSERT_TRUE(write_state(dir.string(), scene, published, 3).has_value());
  EXPECT_FALSE(fs::exists(dir / "scene.state.tmp"));
  auto back = read_state(dir.string());
  ASSERT_TRUE(back.has_value()) << back.error().message;
  ASSERT_TRUE(back->has_value());
  EXPECT_EQ((*back)->state.scene.state_hash(), scene.state_hash());
  EXPECT_EQ((*back)->state.scene.nodes(), scene.nodes());
  EXPECT_EQ((*back)->state.scene.animations(), scene.animations());
  EXPECT_EQ((*back)->state.published, published);
  EXPECT_EQ((*back)->state.sequence, 3u);
  EXPECT_TRUE((*back)->warning.empty());

  // A second write replaces the first completely.
  const Scene other = random_scene(8, 300);
  ASSERT_TRUE(write_state(dir.string(), other, {}, 4).has_value());
  back = read_state(dir.string());
  ASSERT_TRUE(back.has_value() && back->has_value());
  EXPECT_EQ((*back)->state.scene.state_hash(), other.state_hash());
  EXPECT_TRUE((*back)->state.published.empty());
  fs::remove_all(dir);
}

TEST(StateFile, MissingFileIsNoState) {
  const fs::path dir = scratch_dir("missing");
  auto s = read_state(dir.string());
  ASSERT_TRUE(s.has_value());
  EXPECT_FALSE(s->has_value());
}

TEST(StateFile, CorruptOrTruncatedFilesAreRefused) {
  const Scene scene = random_scene(9, 500);
  const auto bytes = encode_state(scene, {"a", "b"}, 1);
  ASSERT_TRUE(decode_state(bytes).has_value());  // positive control
  // Every truncation and a flip of every 7th byte: an error, never a crash.
  for (std::size_t n = 0; n < bytes.size(); n += 13) {
    auto cut = std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + std::ptrdiff_t(n));
    EXPECT_FALSE(decode_state(cut).has_value()) << "truncated at " << n;
  }
  for (std::size_t i = 0; i < bytes.size(); i += 7) {
    auto flipped = bytes;
    flipped[i] ^= 0x5a;
    EXPECT_FALSE(decode_state(flipped).has_value()) << "flipped byte " << i;
  }
  const fs::path dir = scratch_dir("corrupt");
  fs::create_directories(dir);
  std::ofstream(dir / "scene.state") << "not a state file";
  auto s = read_state(dir.string());
  ASSERT_FALSE(s.has_value());
  EXPECT_NE(s.error().message.find("scene.state: corrupt state file"), std::string::npos)
      << s.error().message;
  fs::remove_all(dir);
}

// The write-ahead slots (scene.wal.0/1, no fsync) and the durable copy (scene.state): the valid
// copy with the highest sequence wins; torn copies are ignored when another is valid.
TEST(StateFile, NewestValidCopyWins) {
  const Scene older = random_scene(10, 400), newer = random_scene(11, 400),
              newest = random_scene(12, 40);
  const fs::path dir = scratch_dir("copies");
  const std::string d = dir.string();
  ASSERT_TRUE(write_durable(d, encode_state(older, {}, 5)).has_value());
  auto wal = WriteAheadLog::open(d);
  ASSERT_TRUE(wal.has_value()) << wal.error().message;
  ASSERT_TRUE(wal->write(encode_state(newer, {"x"}, 6), 6).has_value());  // slot 0
  auto got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->state.scene.state_hash(), newer.state_hash());
  EXPECT_EQ((*got)->path, wal_path(d, 0));
  // A smaller record overwrites the slot in place (old bytes after it are ignored).
  ASSERT_TRUE(wal->write(encode_state(newest, {}, 8), 8).has_value());  // slot 0 again
  got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->state.scene.state_hash(), newest.state_hash());
  ASSERT_TRUE(wal->write(encode_state(newer, {}, 9), 9).has_value());  // slot 1
  got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->path, wal_path(d, 1));

  // A torn newest slot (killed mid-write): the other slot, the previous state.
  {
    std::fstream f(wal_path(d, 1), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.write("torn", 4);
  }
  got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->state.scene.state_hash(), newest.state_hash());
  EXPECT_EQ((*got)->state.sequence, 8u);

  // A durable copy written later (higher sequence) wins over the write-ahead slots.
  ASSERT_TRUE(write_state(d, older, {}, 10).has_value());
  got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->state.scene.state_hash(), older.state_hash());
  EXPECT_TRUE((*got)->warning.empty());

  // A garbage durable copy: a write-ahead slot, with a warning naming the file.
  std::ofstream(dir / "scene.state", std::ios::trunc) << "garbage";
  got = read_state(d);
  ASSERT_TRUE(got.has_value() && got->has_value());
  EXPECT_EQ((*got)->state.sequence, 8u);
  EXPECT_NE((*got)->warning.find("scene.state: corrupt state file"), std::string::npos);

  // Everything torn: an error naming the files.
  std::ofstream(wal_path(d, 0), std::ios::trunc) << "garbage!garbage!";
  got = read_state(d);
  ASSERT_FALSE(got.has_value());
  EXPECT_NE(got.error().message.find("scene.state"), std::string::npos);
  EXPECT_NE(got.error().message.find("scene.wal.0"), std::string::npos);
  fs::remove_all(dir);
}

// scene/node/scene.example.yaml documents every key: it reads strictly (common and server keys,
// nothing unknown) to the values it names.
TEST(SceneConfig, ExampleConfigReadsStrictly) {
  const std::string path = std::string(STUDIO_SOURCE_DIR) + "/scene/node/scene.example.yaml";
  auto doc = yaml::load_file(path);
  ASSERT_TRUE(doc.has_value()) << doc.error().message;
  auto map = yaml::MapReader::from(*doc);
  ASSERT_TRUE(map.has_value());
  ASSERT_TRUE(runtime::read_common_options(*map).has_value());
  auto o = read_node_options(*map);
  ASSERT_TRUE(o.has_value()) << o.error().message;
  ASSERT_TRUE(map->finish().has_value()) << map->finish().error().message;
  EXPECT_EQ(o->period_ns, 40'000'000);
  EXPECT_EQ(o->clock_source, ClockSource::studio);
  EXPECT_EQ(o->state_dir, "/var/lib/studio/scene");
  EXPECT_EQ(o->scene_file, std::string(STUDIO_SOURCE_DIR) + "/scene/data/scene.yaml");
  EXPECT_EQ(o->persist_interval, 1.0);
  EXPECT_EQ(o->command_queue, 16384);
  EXPECT_EQ(o->frame_at(o->epoch_ns + 3 * o->period_ns + 1), 3);
  EXPECT_EQ(o->frame_at(o->epoch_ns - 1), -1);
}

}  // namespace
}  // namespace studio::scene::node

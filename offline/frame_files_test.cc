// The sequence files (offline/frame_files.h): a frame file verifies, any damage is refused by
// reason, the bytes depend only on the content, and a DCC importer (assimp, the one scene/ uses)
// loads both a frame (positions, normals, vertex colours) and the index (one mesh per frame, the
// flip-book animation).
#include "offline/frame_files.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <assimp/Importer.hpp>
#include <filesystem>
#include <fstream>

#include "hull/segment_mesh.h"
#include "hull/segment_set.h"

namespace fs = std::filesystem;

namespace studio::offline {
namespace {

hull::Mesh box_mesh(float size) {
  hull::GridSpec g;
  g.box_min = {0, 0, 0};
  g.box_max = {1, 1, 1};
  g.cells_u = g.cells_v = 4;
  std::vector<std::vector<hull::Interval>> cols(g.columns());
  for (int j = 1; j < 3; ++j)
    for (int i = 1; i < 3; ++i) cols[std::size_t(i + 4 * j)].push_back({0.2f, 0.2f + size});
  return hull::segment_marching_cubes(hull::SegmentSet::from_columns(g, cols));
}

std::vector<Eigen::Vector3f> colours_of(const hull::Mesh& m) {
  std::vector<Eigen::Vector3f> c;
  for (std::size_t n = 0; n < m.vertices.size(); ++n)
    c.emplace_back(float(n % 256), 128, 255 - float(n % 256));
  return c;
}

TEST(FrameFiles, NamesAreSequenceFriendly) {
  EXPECT_EQ(frame_file_name("actor", 123), "actor_000123.glb");
  EXPECT_EQ(frame_file_name("take_7", 1234567), "take_7_1234567.glb");
  EXPECT_EQ(index_file_name("actor"), "actor.gltf");
}

TEST(FrameFiles, FrameVerifiesAndDamageIsRefused) {
  const hull::Mesh m = box_mesh(0.5f);
  const auto c = colours_of(m);
  const auto bytes = encode_frame_glb(m, &c, "actor_000007", 7);
  EXPECT_EQ(bytes, encode_frame_glb(m, &c, "actor_000007", 7));  // deterministic
  auto info = verify_frame_glb(bytes);
  ASSERT_TRUE(info) << info.error().message;
  EXPECT_EQ(info->frame, 7);
  EXPECT_EQ(info->vertices, m.vertices.size());
  EXPECT_EQ(info->triangles, m.triangles.size());
  EXPECT_TRUE(info->coloured);
  // Truncated, a flipped data byte, a foreign file: each refused with its reason.
  auto cut = bytes;
  cut.resize(bytes.size() - 10);
  ASSERT_FALSE(verify_frame_glb(cut));
  EXPECT_NE(verify_frame_glb(cut).error().message.find("truncated"), std::string::npos);
  auto flipped = bytes;
  flipped[bytes.size() - 5] ^= 1;
  ASSERT_FALSE(verify_frame_glb(flipped));
  EXPECT_NE(verify_frame_glb(flipped).error().message.find("hash"), std::string::npos);
  ASSERT_FALSE(verify_frame_glb(std::vector<uint8_t>(100, 7)));
  // The settings' fingerprint travels with the frame.
  auto tagged = verify_frame_glb(encode_frame_glb(m, &c, "a", 1, fingerprint("grid 256")));
  ASSERT_TRUE(tagged);
  EXPECT_EQ(tagged->options, fingerprint("grid 256"));
  EXPECT_NE(fingerprint("grid 256"), fingerprint("grid 512"));
  // Untextured frames verify too.
  auto plain = verify_frame_glb(encode_frame_glb(m, nullptr, "a", 1));
  ASSERT_TRUE(plain);
  EXPECT_FALSE(plain->coloured);
}

TEST(FrameFiles, ImporterLoadsFramesAndIndex) {
  const fs::path dir =
      fs::temp_directory_path() / ("offline_frame_files_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::vector<FrameFileInfo> infos;
  std::vector<std::size_t> vertices;
  for (int f = 10; f < 13; ++f) {
    const hull::Mesh m = box_mesh(0.2f + 0.1f * float(f - 10));
    const auto c = colours_of(m);
    const auto bytes = encode_frame_glb(m, &c, "actor_" + std::to_string(f), f);
    const std::string path = (dir / frame_file_name("actor", f)).string();
    ASSERT_TRUE(write_file_atomic(path, bytes));
    auto info = verify_frame_file(path);
    ASSERT_TRUE(info) << info.error().message;
    infos.push_back(*info);
    vertices.push_back(m.vertices.size());
  }
  const std::string index = encode_index_gltf("actor", 25, infos);
  std::ofstream(dir / index_file_name("actor")) << index;
  {
    Assimp::Importer importer;
    const aiScene* s = importer.ReadFile((dir / "actor_000011.glb").string(), 0);
    ASSERT_NE(s, nullptr) << importer.GetErrorString();
    ASSERT_EQ(s->mNumMeshes, 1u);
    EXPECT_EQ(s->mMeshes[0]->mNumVertices, vertices[1]);
    EXPECT_TRUE(s->mMeshes[0]->HasVertexColors(0));
    EXPECT_TRUE(s->mMeshes[0]->HasNormals());
  }
  {
    Assimp::Importer importer;
    const aiScene* s = importer.ReadFile((dir / "actor.gltf").string(), 0);
    ASSERT_NE(s, nullptr) << importer.GetErrorString();
    ASSERT_EQ(s->mNumMeshes, 3u);
    for (unsigned k = 0; k < 3; ++k) {
      EXPECT_EQ(s->mMeshes[k]->mNumVertices, vertices[k]);
      EXPECT_TRUE(s->mMeshes[k]->HasVertexColors(0));
    }
    ASSERT_EQ(s->mNumAnimations, 1u);
    EXPECT_EQ(s->mAnimations[0]->mNumChannels, 3u);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace studio::offline

#include "hull/mesh_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

namespace studio::hull {
namespace {

Mesh one_column() {
  GridSpec g;
  g.cells_u = g.cells_v = 1;
  return segment_marching_cubes(SegmentSet::from_columns(g, {{{0.25f, 0.75f}}}));
}

TEST(MeshIo, PlyHeaderAndSize) {
  const Mesh m = one_column();
  const auto b = encode_ply(m);
  const std::string s(b.begin(), b.end());
  const std::size_t end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_NE(s.find("element vertex " + std::to_string(m.vertices.size())), std::string::npos);
  EXPECT_EQ(b.size(), end + 11 + m.vertices.size() * 24 + m.triangles.size() * 13);
}

TEST(MeshIo, ObjCounts) {
  const Mesh m = one_column();
  const std::string s = encode_obj(m);
  std::size_t v = 0, f = 0;
  for (std::size_t p = 0; (p = s.find('\n', p)) != std::string::npos; ++p) {
    if (s.compare(p + 1, 2, "v ") == 0) ++v;
    if (s.compare(p + 1, 2, "f ") == 0) ++f;
  }
  EXPECT_EQ(v, m.vertices.size());
  EXPECT_EQ(f, m.triangles.size());
}

TEST(MeshIo, GlbStructure) {
  const Mesh m = one_column();
  const auto b = encode_glb(m);
  uint32_t h[5];
  std::memcpy(h, b.data(), sizeof h);
  EXPECT_EQ(h[0], 0x46546C67u);
  EXPECT_EQ(h[1], 2u);
  EXPECT_EQ(h[2], b.size());
  EXPECT_EQ(h[3] % 4, 0u);
  const std::string json(b.begin() + 20, b.begin() + 20 + h[3]);
  EXPECT_NE(json.find("\"POSITION\":0"), std::string::npos);
  uint32_t bin_len;
  std::memcpy(&bin_len, b.data() + 20 + h[3], 4);
  EXPECT_EQ(bin_len, m.vertices.size() * 24 + m.triangles.size() * 12);
}

TEST(MeshIo, WriteByExtensionAndRejectUnknown) {
  const Mesh m = one_column();
  const auto dir = std::filesystem::temp_directory_path() / "hull_mesh_io_test";
  std::filesystem::create_directories(dir);
  for (const char* name : {"a.ply", "a.obj", "a.glb"}) {
    ASSERT_TRUE(write_mesh(m, (dir / name).string()));
    EXPECT_GT(std::filesystem::file_size(dir / name), 100u);
  }
  EXPECT_FALSE(write_mesh(m, (dir / "a.stl").string()));
  EXPECT_FALSE(write_mesh(m, "/nonexistent-dir/x.ply"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace studio::hull

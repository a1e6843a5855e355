#include "hull/segment_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hull/silhouette_cut.h"
#include "support/cameras.h"
#include "testing/synthetic.h"

namespace studio::hull {
namespace {

void expect_closed(const Mesh& mesh, const SegmentSet& set, double tolerance) {
  const MeshTopology topo = check_topology(mesh);
  EXPECT_GT(topo.edges, 0u);
  EXPECT_EQ(topo.boundary_edges, 0u);
  EXPECT_EQ(topo.non_manifold_edges, 0u);
  EXPECT_EQ(topo.inconsistent_edges, 0u);
  EXPECT_EQ(topo.degenerate_triangles, 0u);
  EXPECT_GT(mesh.volume(), 0);
  EXPECT_NEAR(mesh.volume() / set.volume(), 1.0, tolerance);
  ASSERT_EQ(mesh.normals.size(), mesh.vertices.size());
  for (const auto& n : mesh.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
}

TEST(SegmentMesh, SingleColumnIsABox) {
  GridSpec g;
  g.cells_u = g.cells_v = 1;
  const SegmentSet s = SegmentSet::from_columns(g, {{{0.25f, 0.75f}}});
  const Mesh m = segment_marching_cubes(s);
  const MeshTopology topo = check_topology(m);
  EXPECT_TRUE(topo.watertight());
  EXPECT_TRUE(topo.oriented());
  // The cross-section of one column is the diamond of its four cells' corner triangles: half the
  // cell area, extruded over the exact interval.
  EXPECT_NEAR(m.volume(), 0.5 * 0.5, 1e-6);
  float lo = 1, hi = 0;
  for (const auto& v : m.vertices) lo = std::min(lo, v.y()), hi = std::max(hi, v.y());
  EXPECT_EQ(lo, 0.25f);
  EXPECT_EQ(hi, 0.75f);
}

TEST(SegmentMesh, RandomSegmentSetsAreClosedManifolds) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0, 1);
  for (Axis axis : {Axis::x, Axis::y, Axis::z}) {
    GridSpec g;
    g.axis = axis;
    g.cells_u = 17;
    g.cells_v = 13;
    std::vector<std::vector<Interval>> cols(g.columns());
    for (auto& c : cols) {
      float t = 0;
      while (true) {
        const float lo = t + 0.3f * U(rng), hi = lo + 0.3f * U(rng) + 0.01f;
        if (hi > 1) break;
        if (U(rng) < 0.7f) c.push_back({lo, hi});
        t = hi + 0.01f;
      }
    }
    const SegmentSet s = SegmentSet::from_columns(g, cols);
    const Mesh m = segment_marching_cubes(s);
    const MeshTopology topo = check_topology(m);
    EXPECT_TRUE(topo.watertight()) << topo.boundary_edges << " " << topo.non_manifold_edges;
    EXPECT_TRUE(topo.oriented()) << topo.inconsistent_edges;
    EXPECT_GT(m.volume(), 0);
  }
}

TEST(SegmentMesh, HullOfAnActorIsWatertightWithTheSegmentVolume) {
  const testing::Scene scene = testing::actor();
  auto cams = support::camera_ring(8, 704, 576, 4.0, 1.6, {0, 1, 0}, 600);
  std::vector<RunMask> masks;
  std::vector<View> views;
  for (const Camera& c : cams) masks.push_back(testing::render_mask(c, scene));
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  for (Axis axis : {Axis::y, Axis::x}) {
    GridSpec g;
    g.box_min = {-1, 0, -1};
    g.box_max = {1, 2, 1};
    g.axis = axis;
    g.cells_u = g.cells_v = 128;
    auto hull = visual_hull(g, views);
    ASSERT_TRUE(hull);
    const Mesh m = segment_marching_cubes(*hull);
    expect_closed(m, *hull, 0.05);
  }
}

// The live hull meshes on two threads (MeshOptions::threads): the same vertices, triangles and
// order as one thread, on the actor's hull (both axes) and on random sets with several segments
// per column and gaps, where the two halves share a lattice row of vertices.
TEST(SegmentMesh, TwoThreadsGiveTheSameMesh) {
  const auto expect_same = [](const SegmentSet& set) {
    const Mesh one = segment_marching_cubes(set, {.threads = 1});
    const Mesh two = segment_marching_cubes(set, {.threads = 2});
    ASSERT_FALSE(one.empty());
    ASSERT_EQ(one.vertices.size(), two.vertices.size());
    ASSERT_EQ(one.triangles.size(), two.triangles.size());
    for (std::size_t k = 0; k < one.vertices.size(); ++k)
      ASSERT_EQ(one.vertices[k], two.vertices[k]) << "vertex " << k;
    for (std::size_t k = 0; k < one.triangles.size(); ++k)
      ASSERT_EQ(one.triangles[k], two.triangles[k]) << "triangle " << k;
    ASSERT_EQ(one.normals.size(), two.normals.size());
    for (std::size_t k = 0; k < one.normals.size(); ++k) ASSERT_EQ(one.normals[k], two.normals[k]);
    EXPECT_TRUE(check_topology(two).watertight());
  };
  const testing::Scene scene = testing::actor();
  auto cams = support::camera_ring(8, 704, 576, 4.0, 1.6, {0, 1, 0}, 600);
  std::vector<RunMask> masks;
  std::vector<View> views;
  for (const Camera& c : cams) masks.push_back(testing::render_mask(c, scene));
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  for (Axis axis : {Axis::y, Axis::x}) {
    GridSpec g;
    g.box_min = {-1, 0, -1};
    g.box_max = {1, 2, 1};
    g.axis = axis;
    g.cells_u = g.cells_v = 160;
    auto hull = visual_hull(g, views);
    ASSERT_TRUE(hull);
    expect_same(*hull);
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0, 1);
  for (int rows : {16, 17, 40}) {
    GridSpec g;
    g.cells_u = 23;
    g.cells_v = rows;
    std::vector<std::vector<Interval>> cols(g.columns());
    for (auto& c : cols) {
      float t = 0;
      while (true) {
        const float lo = t + 0.3f * U(rng), hi = lo + 0.3f * U(rng) + 0.01f;
        if (hi > 1) break;
        if (U(rng) < 0.7f) c.push_back({lo, hi});
        t = hi + 0.01f;
      }
    }
    expect_same(SegmentSet::from_columns(g, cols));
  }
}

TEST(SegmentMesh, SphereMeshVolumeMatchesSphereHull) {
  testing::Scene s;
  s.ellipsoids.push_back({Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::Constant(0.5)});
  auto cams = support::camera_ring(12, 640, 480, 5.0, 1.0, {0, 1, 0}, 700);
  cams.push_back(support::look_at_camera("top", {0, 6, 0}, {0, 1, 0}, Eigen::Vector3d::UnitZ(), 640,
                                         480, 700));
  std::vector<RunMask> masks;
  std::vector<View> views;
  for (const Camera& c : cams) masks.push_back(testing::render_mask(c, s));
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  GridSpec g;
  g.box_min = {-0.6, 0.4, -0.6};
  g.box_max = {0.6, 1.6, 0.6};
  g.cells_u = g.cells_v = 96;
  auto hull = visual_hull(g, views);
  ASSERT_TRUE(hull);
  const Mesh m = segment_marching_cubes(*hull);
  expect_closed(m, *hull, 0.02);
  // Vertex normals of the sphere point outward.
  int outward = 0;
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    outward += m.normals[k].dot(m.vertices[k] - Eigen::Vector3f(0, 1, 0)) > 0;
  }
  EXPECT_GT(outward, int(0.99 * m.vertices.size()));
}

}  // namespace
}  // namespace studio::hull

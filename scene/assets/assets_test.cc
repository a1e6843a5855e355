// Assets: the generated default scene read back through assimp (an independent check of the
// generator's GLB), OBJ with an external texture, content hashes, a set as scene nodes with its
// animation on the scene clock.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "scene/scene.h"
#include "scene_assets/asset.h"
#include "scene_assets/content_hash.h"
#include "scene_assets/instantiate.h"

using namespace studio;
using namespace studio::scene_assets;
namespace fs = std::filesystem;

namespace {

const std::string kMuseum = std::string(STUDIO_SCENE_DEFAULT_DIR) + "/museum.glb";

fs::path temp_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("scene_assets_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(ContentHash, Sha256KnownVectorsAndFiles) {
  const std::string abc = "abc";
  EXPECT_EQ(sha256_hex(reinterpret_cast<const std::uint8_t*>(abc.data()), abc.size()),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(nullptr, 0),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  const fs::path d = temp_dir("hash");
  std::ofstream(d / "f.bin") << "abc";
  EXPECT_EQ(*sha256_file((d / "f.bin").string()),
            sha256_hex(reinterpret_cast<const std::uint8_t*>(abc.data()), 3));
  auto missing = sha256_file((d / "none.bin").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("none.bin"), std::string::npos);
  fs::remove_all(d);
}

TEST(Museum, GeneratedSceneMeetsTheBrief) {
  auto a = load_asset(kMuseum);
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_GE(a->triangle_count(), 50000u);
  EXPECT_GE(a->textures.size(), 4u);
  for (const Texture& t : a->textures) {
    EXPECT_GE(t.width, 256);
    EXPECT_EQ(t.rgba.size(), static_cast<std::size_t>(t.width * t.height * 4));
  }
  EXPECT_GE(a->lights.size(), 3u);
  int light_nodes = 0;
  for (const AssetNode& n : a->nodes) {
    light_nodes += n.light >= 0;
    // Each light hangs under the hall's root (the generator once attached them through a
    // reference that add_node had invalidated: ASan, heap-use-after-free).
    if (n.light >= 0) EXPECT_GE(n.parent, 0) << n.name;
  }
  EXPECT_GE(light_nodes, 3);
  EXPECT_EQ(a->sha256, *sha256_file(kMuseum));

  // Named exhibits with distinct colours.
  const char* names[] = {"exhibit_red_sphere",  "exhibit_green_torus",  "exhibit_blue_vase",
                         "exhibit_yellow_knot", "exhibit_magenta_cone", "exhibit_cyan_cube"};
  std::vector<Eigen::Vector4f> colours;
  for (const char* name : names) {
    const int i = a->find_node(name);
    ASSERT_GE(i, 0) << name;
    ASSERT_EQ(a->nodes[i].meshes.size(), 1u);
    const MeshData& m = a->meshes[a->nodes[i].meshes[0]];
    ASSERT_GE(m.material, 0);
    colours.push_back(a->materials[m.material].base_colour);
  }
  for (std::size_t i = 0; i < colours.size(); ++i)
    for (std::size_t j = i + 1; j < colours.size(); ++j)
      EXPECT_GT((colours[i] - colours[j]).norm(), 0.5f) << names[i] << " vs " << names[j];

  ASSERT_EQ(a->animations.size(), 1u);
  EXPECT_EQ(a->animations[0].name, "flight");
  EXPECT_NEAR(a->animations[0].duration(), 8.0, 1e-6);
}

TEST(Museum, FlyerPassesCloseToTheActorOnTheSceneClock) {
  auto a = load_asset(kMuseum);
  ASSERT_TRUE(a) << a.error().message;
  const Instance inst = instantiate(*a, "set", "", 0);
  scene::Scene s;
  ASSERT_TRUE(s.apply({0, scene::Batch{inst.commands}}));
  ASSERT_NE(s.find("set/exhibit_red_sphere"), nullptr);
  EXPECT_EQ(s.find("set/exhibit_red_sphere")->kind, scene::NodeKind::model);
  EXPECT_EQ(s.find("set/light_stage")->kind, scene::NodeKind::light);
  ASSERT_TRUE(s.animations().contains("set/flight"));
  ASSERT_TRUE(s.apply({0, scene::Play{"set/flight"}}));
  const Eigen::Vector3d head(0, 1.7, 0);
  double nearest = 1e9, farthest = 0;
  for (std::int64_t f = 0; f < 200; f += 2) {  // 8 s at 25 fps
    ASSERT_TRUE(s.apply({f, scene::Tick{}}));
    const Eigen::Vector3d p = s.world_from_node("set/flyer")->col(3).head<3>();
    nearest = std::min(nearest, (p - head).norm());
    farthest = std::max(farthest, (p - head).norm());
  }
  EXPECT_LT(nearest, 1.3);   // passes close to the actor
  EXPECT_GT(farthest, 5.0);  // and flies around the hall
  // Exhibit bounds from the asset: the red sphere (r = 0.5) on its pedestal at x = -7.5.
  const Eigen::AlignedBox3d box = world_bounds(s, "set/exhibit_red_sphere", *a);
  EXPECT_TRUE(box.center().isApprox(Eigen::Vector3d(-7.5, 1.55, -8), 1e-3));
  EXPECT_NEAR(box.sizes().x(), 1.0, 1e-3);
}

TEST(Assets, ObjWithMaterialAndExternalTexture) {
  const fs::path d = temp_dir("obj");
  cv::Mat img(8, 8, CV_8UC3, cv::Scalar(0, 0, 255));  // red (BGR)
  img.row(0).setTo(cv::Scalar(255, 0, 0));            // top row blue
  cv::imwrite((d / "red.png").string(), img);
  std::ofstream(d / "quad.mtl") << "newmtl paint\nKd 0.5 0.25 1.0\nmap_Kd red.png\n";
  std::ofstream(d / "quad.obj")
      << "mtllib quad.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl paint\nf 1/1 2/2 3/3 4/4\n";
  auto a = load_asset((d / "quad.obj").string());
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_EQ(a->meshes.size(), 1u);
  EXPECT_EQ(a->triangle_count(), 2u);  // the quad, triangulated
  const MaterialData& m = a->materials[a->meshes[0].material];
  EXPECT_TRUE(m.base_colour.head<3>().isApprox(Eigen::Vector3f(0.5f, 0.25f, 1.0f)));
  ASSERT_GE(m.texture, 0);
  const Texture& t = a->textures[m.texture];
  ASSERT_EQ(t.width, 8);
  // Bottom row first: the image's top (blue) row is the last row.
  EXPECT_EQ(t.rgba[0], 255);                // R of the bottom-left pixel (red)
  EXPECT_EQ(t.rgba[(7 * 8) * 4 + 2], 255);  // B of the top-left pixel (blue)
  EXPECT_EQ(a->meshes[0].uvs.size(), a->meshes[0].positions.size());
  fs::remove_all(d);
}

TEST(Assets, MissingAndCorruptFilesAreOneLineErrors) {
  auto missing = load_asset("/nonexistent/set.glb");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message.find('\n'), std::string::npos);
  const fs::path d = temp_dir("corrupt");
  std::ofstream(d / "bad.glb") << "glTF this is not a binary gltf file";
  auto bad = load_asset((d / "bad.glb").string());
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("bad.glb"), std::string::npos);
  EXPECT_EQ(bad.error().message.find('\n'), std::string::npos);
  fs::remove_all(d);
}

TEST(Assets, CacheLoadsOnce) {
  AssetCache cache;
  auto a = cache.load(kMuseum);
  ASSERT_TRUE(a);
  auto b = cache.load(kMuseum);
  ASSERT_TRUE(b);
  EXPECT_EQ(a->get(), b->get());
  EXPECT_EQ(cache.find(kMuseum).get(), a->get());
  EXPECT_EQ(cache.find("other.glb"), nullptr);
}

#pragma once
// A loaded asset file (a virtual set or an object): meshes, materials, textures (embedded ones
// included), the node hierarchy, lights (KHR_lights_punctual) and node animations, read through
// assimp from glTF 2.0 (.gltf/.glb), OBJ and the other formats assimp knows (PLY for meshes).
// Pure data: no GL. Coordinates as stored in the file (glTF: metres, y up, the studio's).

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/animation.h"
#include "scene/node.h"
#include "scene/transform.h"

namespace studio::scene_assets {

// RGBA8, `height` rows of `width` pixels, bottom row first (OpenGL's order: texture coordinate
// v = 0 is the bottom of the image, assimp's convention for every format).
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

struct MaterialData {
  std::string name;
  Eigen::Vector4f base_colour = Eigen::Vector4f::Ones();  // glTF baseColorFactor / diffuse
  int texture = -1;                                        // index into Asset::textures, -1 none
  Eigen::Vector3f emissive = Eigen::Vector3f::Zero();
};

// Triangles only; normals always present (generated where the file has none); uvs empty or
// one per vertex.
struct MeshData {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3f> colours;  // empty or one RGB per vertex (PLY, glTF COLOR_0)
  std::vector<std::uint32_t> indices;
  int material = -1;
  Eigen::AlignedBox3f bounds;  // of positions, in the mesh's frame
};

// The file's node hierarchy, parents before children; nodes[0] is the root.
struct AssetNode {
  std::string name;
  int parent = -1;
  scene::Transform local;
  std::vector<std::uint32_t> meshes;
  int light = -1;  // index into Asset::lights
};

struct Asset {
  std::string path;
  std::string sha256;
  std::vector<MeshData> meshes;
  std::vector<MaterialData> materials;
  std::vector<Texture> textures;
  std::vector<AssetNode> nodes;
  std::vector<scene::Light> lights;
  // Node animations; every track's `node` is the name of an AssetNode. Times in seconds.
  std::vector<scene::Animation> animations;

  std::size_t triangle_count() const;
  int find_node(const std::string& name) const;  // -1 when absent
};

// Loads a file. Errors are one line: "museum.glb: <assimp's message>", "x.glb: no meshes",
// "x.glb: texture '*3': cannot decode". The path is stored as given.
Expected<Asset> load_asset(const std::string& path);

}  // namespace studio::scene_assets

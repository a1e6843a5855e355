#pragma once
// A minimal glTF 2.0 binary (GLB) writer for the demo-scene generator: one buffer (the BIN
// chunk), triangle meshes (POSITION, NORMAL, TEXCOORD_0, uint32 indices), PBR materials with an
// embedded PNG base-colour texture, nodes with TRS, KHR_lights_punctual lights and LINEAR node
// animations. Layout per the glTF 2.0 specification, section "Binary glTF Layout".

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace studio::scene_tools {

struct MeshBuild {
  std::vector<Eigen::Vector3f> positions, normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<std::uint32_t> indices;
  // Appends another mesh (indices shifted).
  void append(const MeshBuild& other);
  // Applies x -> R x + t (normals rotated).
  MeshBuild transformed(const Eigen::Matrix3f& R, const Eigen::Vector3f& t) const;
  std::size_t triangles() const { return indices.size() / 3; }
};

struct GltfNode {
  std::string name;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  int mesh = -1;
  int light = -1;
  std::vector<int> children;
};

class GlbWriter {
 public:
  // PNG bytes -> texture index.
  int add_texture_png(const std::string& name, const std::vector<std::uint8_t>& png);
  int add_material(const std::string& name, const Eigen::Vector4f& base_colour, int texture,
                   const Eigen::Vector3f& emissive = Eigen::Vector3f::Zero());
  int add_mesh(const std::string& name, const MeshBuild& mesh, int material);
  int add_node(const GltfNode& node);
  // Valid until the next add_node (which may reallocate the nodes).
  GltfNode& node(int index) { return nodes_[static_cast<std::size_t>(index)]; }
  // type: "point" | "directional" | "spot".
  int add_light(const std::string& name, const std::string& type, const Eigen::Vector3f& colour,
                float intensity);
  // One LINEAR sampler per channel; rotation values are quaternions (x, y, z, w).
  void add_animation(const std::string& name, int node, const std::vector<float>& times,
                     const std::vector<Eigen::Vector3f>& translations,
                     const std::vector<Eigen::Vector4f>& rotations);
  // The whole file; roots are the nodes no other node lists as a child.
  std::vector<std::uint8_t> bytes() const;

 private:
  int view(const void* data, std::size_t size, int target);
  int accessor(int view, int component_type, std::size_t count, const std::string& type,
               const std::string& min_max = "");
  std::vector<std::uint8_t> bin_;
  std::vector<std::string> views_, accessors_, images_, textures_, materials_, meshes_, lights_,
      animations_;
  std::vector<GltfNode> nodes_;
};

}  // namespace studio::scene_tools

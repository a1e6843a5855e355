#pragma once
// One node of the scene graph (the paper's virtual scene server holds the master copy of the
// virtual set, the animated virtual objects and the live actor; TCSVT 2004 §V).
//
// A node has an id (unique, the DDS key of SceneNode), a parent ("" = the root), a local transform
// (parent_from_node), a kind and the data of its kind:
//   group  - only a transform (a set's root, an empty glTF node)
//   model  - draws meshes of an asset, named by path + content hash, with a material
//   light  - a light (KHR_lights_punctual: point, directional, spot) at the node's origin; a
//            directional or spot light shines along the node's -z axis
//   actor  - the live actor, bound to the ActorMesh and HeadPose streams of `actor_id`; its mesh
//            arrives in the studio frame, so an actor node normally sits at the root with the
//            identity transform
// and a visibility flag (an invisible node hides its whole subtree).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/transform.h"

namespace studio::scene {

using NodeId = std::string;

enum class NodeKind : std::uint8_t { group = 0, model = 1, light = 2, actor = 3 };

// An asset file named by path and content hash (SHA-256 of the file's bytes, lowercase hex; see
// scene_assets/content_hash.h). A renderer that lacks the file or holds different bytes can say
// so by comparing the hash. `meshes` are indices into the asset's mesh list (assimp order); empty
// = every mesh the asset's root node draws.
struct AssetRef {
  std::string path;
  std::string sha256;
  std::vector<std::uint32_t> meshes;
  bool operator==(const AssetRef&) const = default;
};

// The node's material. `colour` multiplies the asset material's base colour (white = as
// authored; for an actor node it is the mesh colour when the mesh has no per-vertex colour).
// `texture` (an image path) replaces the asset's base-colour texture when not empty.
// `high_contrast` (paper §V-F: virtual objects the actor must see clearly when projected onto
// the backdrop) draws the node emissive, unlit, at full intensity of its colour.
struct Material {
  Eigen::Vector4f colour = Eigen::Vector4f::Ones();
  std::string texture;
  bool high_contrast = false;
  bool operator==(const Material&) const = default;
};

enum class LightType : std::uint8_t { point = 0, directional = 1, spot = 2 };

// KHR_lights_punctual: colour (linear RGB), intensity (candela for point/spot, lux for
// directional), range (0 = infinite), spot cone angles (radians).
struct Light {
  LightType type = LightType::point;
  Eigen::Vector3f colour = Eigen::Vector3f::Ones();
  float intensity = 1.0f;
  float range = 0.0f;
  float inner_cone = 0.0f;
  float outer_cone = 0.785398f;
  bool operator==(const Light&) const = default;
};

struct Node {
  NodeId id;
  NodeId parent;  // "" = child of the root
  NodeKind kind = NodeKind::group;
  Transform local;  // parent_from_node
  bool visible = true;
  AssetRef asset;         // kind == model
  Material material;      // model and actor
  Light light;            // kind == light
  std::string actor_id;   // kind == actor

  // Studio frame at which `local` was last set (by a command or an animation evaluated at that
  // frame); renderers draw the latest. Part of the state.
  std::int64_t frame = 0;

  // Self-consistency only (the Scene checks ids against each other): a non-empty id without
  // control characters, a valid transform, a model with an asset path, an actor with an actor
  // id, finite material and light numbers (colour in [0, 1], intensity >= 0, range >= 0,
  // 0 <= inner_cone <= outer_cone <= pi/2).
  Expected<void> validate() const;

  bool operator==(const Node&) const = default;
};

const char* to_string(NodeKind kind);
const char* to_string(LightType type);

}  // namespace studio::scene

// Reading an asset file through assimp into the plain Asset structure.
#include <assimp/GltfMaterial.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "scene_assets/asset.h"
#include "scene_assets/content_hash.h"

namespace studio::scene_assets {
namespace {

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// cv::Mat (BGR, BGRA or grey, top row first) -> RGBA bottom row first.
Texture to_texture(const std::string& name, const cv::Mat& image) {
  cv::Mat rgba;
  if (image.channels() == 1)
    cv::cvtColor(image, rgba, cv::COLOR_GRAY2RGBA);
  else if (image.channels() == 3)
    cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA);
  else
    cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA);
  if (rgba.depth() != CV_8U) rgba.convertTo(rgba, CV_8U, 1.0 / 257);
  cv::flip(rgba, rgba, 0);
  Texture t;
  t.name = name;
  t.width = rgba.cols;
  t.height = rgba.rows;
  t.rgba.assign(rgba.data, rgba.data + rgba.total() * 4);
  return t;
}

Expected<Texture> read_texture(const aiScene* scene, const std::string& ref,
                               const std::filesystem::path& folder) {
  if (const aiTexture* t = scene->GetEmbeddedTexture(ref.c_str())) {
    if (t->mHeight == 0) {  // compressed (PNG, JPEG): mWidth bytes
      const cv::Mat bytes(1, static_cast<int>(t->mWidth), CV_8U, t->pcData);
      const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
      if (image.empty()) return fail("texture '" + ref + "': cannot decode");
      return to_texture(ref, image);
    }
    // Uncompressed texels, BGRA8, top row first.
    const cv::Mat bgra(static_cast<int>(t->mHeight), static_cast<int>(t->mWidth), CV_8UC4,
                       t->pcData);
    return to_texture(ref, bgra);
  }
  const std::filesystem::path file = folder / ref;
  const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) return fail("texture '" + file.string() + "': cannot read");
  return to_texture(ref, image);
}

scene::Transform to_transform(const aiMatrix4x4& m) {
  aiVector3D s, t;
  aiQuaternion q;
  m.Decompose(s, q, t);
  scene::Transform out;
  out.translation = {t.x, t.y, t.z};
  out.rotation = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
  out.scale = {s.x, s.y, s.z};
  // A degenerate matrix from a file must not produce an invalid transform.
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(out.scale[i]) || std::abs(out.scale[i]) < 1e-9) out.scale[i] = 1e-6;
  if (!out.rotation.coeffs().allFinite()) out.rotation = Eigen::Quaterniond::Identity();
  if (!out.translation.allFinite()) out.translation.setZero();
  return out;
}

scene::Light to_light(const aiLight& l) {
  scene::Light out;
  switch (l.mType) {
    case aiLightSource_DIRECTIONAL: out.type = scene::LightType::directional; break;
    case aiLightSource_SPOT: out.type = scene::LightType::spot; break;
    default: out.type = scene::LightType::point; break;
  }
  // assimp folds the intensity into the colour.
  const Eigen::Vector3f c(l.mColorDiffuse.r, l.mColorDiffuse.g, l.mColorDiffuse.b);
  const float peak = c.allFinite() ? std::max(c.maxCoeff(), 0.0f) : 0.0f;
  out.intensity = peak;
  out.colour = peak > 0 ? Eigen::Vector3f(c / peak) : Eigen::Vector3f::Ones();
  const float half_pi = std::numbers::pi_v<float> / 2;
  out.outer_cone = std::clamp(std::isfinite(l.mAngleOuterCone) ? l.mAngleOuterCone : half_pi, 0.0f,
                              half_pi);
  out.inner_cone = std::clamp(std::isfinite(l.mAngleInnerCone) ? l.mAngleInnerCone : 0.0f, 0.0f,
                              out.outer_cone);
  return out;
}

}  // namespace

std::size_t Asset::triangle_count() const {
  std::size_t n = 0;
  for (const MeshData& m : meshes) n += m.indices.size() / 3;
  return n;
}

int Asset::find_node(const std::string& name) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

Expected<Asset> load_asset(const std::string& path) {
  auto hash = sha256_file(path);
  if (!hash) return std::unexpected(hash.error());
  Assimp::Importer importer;
  // Points and lines are dropped: the renderer draws triangles.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* ai = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                aiProcess_ValidateDataStructure);
  if (!ai || !ai->mRootNode) return fail(path + ": " + one_line(importer.GetErrorString()));
  if ((ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || ai->mNumMeshes == 0)
    return fail(path + ": no meshes");

  Asset a;
  a.path = path;
  a.sha256 = *hash;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();

  std::map<std::string, int> texture_index;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    const aiMaterial* m = ai->mMaterials[i];
    MaterialData md;
    md.name = m->GetName().C_Str();
    aiColor4D c;
    if (m->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
      md.base_colour = Eigen::Vector4f(c.r, c.g, c.b, c.a).cwiseMax(0.0f).cwiseMin(1.0f);
    aiColor3D e;
    if (m->Get(AI_MATKEY_COLOR_EMISSIVE, e) == AI_SUCCESS)
      md.emissive = Eigen::Vector3f(e.r, e.g, e.b).cwiseMax(0.0f);
    aiString tex;
    if (m->GetTexture(aiTextureType_BASE_COLOR, 0, &tex) == AI_SUCCESS ||
        m->GetTexture(aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS) {
      const std::string ref = tex.C_Str();
      auto it = texture_index.find(ref);
      if (it == texture_index.end()) {
        auto t = read_texture(ai, ref, folder);
        if (!t) return fail(path + ": " + t.error().message);
        it = texture_index.emplace(ref, static_cast<int>(a.textures.size())).first;
        a.textures.push_back(std::move(*t));
      }
      md.texture = it->second;
    }
    a.materials.push_back(std::move(md));
  }

  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    const aiMesh* m = ai->mMeshes[i];
    MeshData md;
    md.name = m->mName.C_Str();
    md.material = static_cast<int>(m->mMaterialIndex) < static_cast<int>(a.materials.size())
                      ? static_cast<int>(m->mMaterialIndex)
                      : -1;
    md.positions.resize(m->mNumVertices);
    md.normals.resize(m->mNumVertices, Eigen::Vector3f::UnitY());
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      md.positions[v] = {m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z};
      if (m->mNormals) md.normals[v] = {m->mNormals[v].x, m->mNormals[v].y, m->mNormals[v].z};
      md.bounds.extend(md.positions[v]);
    }
    if (m->HasTextureCoords(0)) {
      md.uvs.resize(m->mNumVertices);
      for (unsigned v = 0; v < m->mNumVertices; ++v)
        md.uvs[v] = {m->mTextureCoords[0][v].x, m->mTextureCoords[0][v].y};
    }
    if (m->HasVertexColors(0)) {
      md.colours.resize(m->mNumVertices);
      for (unsigned v = 0; v < m->mNumVertices; ++v)
        md.colours[v] = Eigen::Vector3f(m->mColors[0][v].r, m->mColors[0][v].g, m->mColors[0][v].b)
                            .cwiseMax(0.0f).cwiseMin(1.0f);
    }
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) md.indices.push_back(face.mIndices[k]);
    }
    a.meshes.push_back(std::move(md));
  }

  std::map<std::string, int> light_of_node;
  for (unsigned i = 0; i < ai->mNumLights; ++i) {
    light_of_node[ai->mLights[i]->mName.C_Str()] = static_cast<int>(a.lights.size());
    a.lights.push_back(to_light(*ai->mLights[i]));
  }

  // Nodes depth first, parents before children.
  std::vector<std::pair<const aiNode*, int>> stack{{ai->mRootNode, -1}};
  while (!stack.empty()) {
    auto [n, parent] = stack.back();
    stack.pop_back();
    AssetNode an;
    an.name = n->mName.C_Str();
    an.parent = parent;
    an.local = to_transform(n->mTransformation);
    for (unsigned k = 0; k < n->mNumMeshes; ++k)
      if (n->mMeshes[k] < a.meshes.size() && !a.meshes[n->mMeshes[k]].indices.empty())
        an.meshes.push_back(n->mMeshes[k]);
    if (auto it = light_of_node.find(an.name); it != light_of_node.end()) an.light = it->second;
    const int index = static_cast<int>(a.nodes.size());
    a.nodes.push_back(std::move(an));
    for (unsigned k = n->mNumChildren; k-- > 0;) stack.emplace_back(n->mChildren[k], index);
  }

  for (unsigned i = 0; i < ai->mNumAnimations; ++i) {
    const aiAnimation* an = ai->mAnimations[i];
    scene::Animation anim;
    anim.name = an->mName.length ? an->mName.C_Str() : "animation" + std::to_string(i);
    anim.mode = scene::PlayMode::loop;
    const double tps = an->mTicksPerSecond > 0 ? an->mTicksPerSecond : 1.0;
    for (unsigned c = 0; c < an->mNumChannels; ++c) {
      const aiNodeAnim* ch = an->mChannels[c];
      auto add = [&](scene::TrackPath p, unsigned n, auto key_at) {
        if (n == 0) return;
        scene::Track t;
        t.node = ch->mNodeName.C_Str();
        t.path = p;
        for (unsigned k = 0; k < n; ++k) {
          auto [time, value] = key_at(k);
          // Drop duplicate times (assimp may repeat the last key).
          if (!t.times.empty() && !(time / tps > t.times.back())) continue;
          t.times.push_back(std::max(0.0, time / tps));
          t.values.push_back(value);
        }
        anim.tracks.push_back(std::move(t));
      };
      add(scene::TrackPath::translation, ch->mNumPositionKeys, [&](unsigned k) {
        const auto& key = ch->mPositionKeys[k];
        return std::pair{key.mTime, Eigen::Vector4d(key.mValue.x, key.mValue.y, key.mValue.z, 0)};
      });
      add(scene::TrackPath::rotation, ch->mNumRotationKeys, [&](unsigned k) {
        const auto& key = ch->mRotationKeys[k];
        return std::pair{key.mTime, Eigen::Vector4d(key.mValue.x, key.mValue.y, key.mValue.z, key.mValue.w)};
      });
      add(scene::TrackPath::scale, ch->mNumScalingKeys, [&](unsigned k) {
        const auto& key = ch->mScalingKeys[k];
        return std::pair{key.mTime, Eigen::Vector4d(key.mValue.x, key.mValue.y, key.mValue.z, 0)};
      });
    }
    if (auto ok = anim.validate(); !ok) return fail(path + ": " + ok.error().message);
    a.animations.push_back(std::move(anim));
  }
  return a;
}

}  // namespace studio::scene_assets

#include "glb_writer.h"

#include <cstdio>
#include <cstring>
#include <set>
#include <sstream>

namespace studio::scene_tools {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string join(const std::vector<std::string>& items) {
  std::string s = "[";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? "," : "") + items[i];
  return s + "]";
}

template <class V>
std::string vec(const V& v) {
  std::vector<std::string> parts;
  for (int i = 0; i < v.size(); ++i) parts.push_back(num(v[i]));
  return join(parts);
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

}  // namespace

void MeshBuild::append(const MeshBuild& o) {
  const auto base = static_cast<std::uint32_t>(positions.size());
  positions.insert(positions.end(), o.positions.begin(), o.positions.end());
  normals.insert(normals.end(), o.normals.begin(), o.normals.end());
  uvs.insert(uvs.end(), o.uvs.begin(), o.uvs.end());
  for (std::uint32_t i : o.indices) indices.push_back(base + i);
}

MeshBuild MeshBuild::transformed(const Eigen::Matrix3f& R, const Eigen::Vector3f& t) const {
  MeshBuild m = *this;
  for (auto& p : m.positions) p = R * p + t;
  for (auto& n : m.normals) n = R * n;
  return m;
}

int GlbWriter::view(const void* data, std::size_t size, int target) {
  while (bin_.size() % 4) bin_.push_back(0);
  const std::size_t offset = bin_.size();
  const auto* p = static_cast<const std::uint8_t*>(data);
  bin_.insert(bin_.end(), p, p + size);
  std::string v = "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
                  ",\"byteLength\":" + std::to_string(size);
  if (target) v += ",\"target\":" + std::to_string(target);
  views_.push_back(v + "}");
  return static_cast<int>(views_.size()) - 1;
}

int GlbWriter::accessor(int view, int component_type, std::size_t count, const std::string& type,
                        const std::string& min_max) {
  accessors_.push_back("{\"bufferView\":" + std::to_string(view) +
                       ",\"componentType\":" + std::to_string(component_type) +
                       ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"" +
                       min_max + "}");
  return static_cast<int>(accessors_.size()) - 1;
}

int GlbWriter::add_texture_png(const std::string& name, const std::vector<std::uint8_t>& png) {
  const int v = view(png.data(), png.size(), 0);
  images_.push_back("{\"name\":" + quoted(name) + ",\"bufferView\":" + std::to_string(v) +
                    ",\"mimeType\":\"image/png\"}");
  textures_.push_back("{\"sampler\":0,\"source\":" + std::to_string(images_.size() - 1) + "}");
  return static_cast<int>(textures_.size()) - 1;
}

int GlbWriter::add_material(const std::string& name, const Eigen::Vector4f& base, int texture,
                            const Eigen::Vector3f& emissive) {
  std::string m = "{\"name\":" + quoted(name) + ",\"pbrMetallicRoughness\":{\"baseColorFactor\":" +
                  vec(base) + ",\"metallicFactor\":0,\"roughnessFactor\":0.7";
  if (texture >= 0) m += ",\"baseColorTexture\":{\"index\":" + std::to_string(texture) + "}";
  m += "},\"emissiveFactor\":" + vec(emissive) + "}";
  materials_.push_back(m);
  return static_cast<int>(materials_.size()) - 1;
}

int GlbWriter::add_mesh(const std::string& name, const MeshBuild& mesh, int material) {
  const std::size_t n = mesh.positions.size();
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (const auto& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int pos = accessor(view(mesh.positions.data(), n * 12, 34962), 5126, n, "VEC3",
                           ",\"min\":" + vec(lo) + ",\"max\":" + vec(hi));
  const int nrm = accessor(view(mesh.normals.data(), n * 12, 34962), 5126, n, "VEC3");
  std::string attributes = "{\"POSITION\":" + std::to_string(pos) + ",\"NORMAL\":" + std::to_string(nrm);
  if (!mesh.uvs.empty()) {
    const int uv = accessor(view(mesh.uvs.data(), n * 8, 34962), 5126, n, "VEC2");
    attributes += ",\"TEXCOORD_0\":" + std::to_string(uv);
  }
  const int idx = accessor(view(mesh.indices.data(), mesh.indices.size() * 4, 34963), 5125,
                           mesh.indices.size(), "SCALAR");
  meshes_.push_back("{\"name\":" + quoted(name) + ",\"primitives\":[{\"attributes\":" + attributes +
                    "},\"indices\":" + std::to_string(idx) + ",\"material\":" +
                    std::to_string(material) + ",\"mode\":4}]}");
  return static_cast<int>(meshes_.size()) - 1;
}

int GlbWriter::add_node(const GltfNode& node) {
  nodes_.push_back(node);
  return static_cast<int>(nodes_.size()) - 1;
}

int GlbWriter::add_light(const std::string& name, const std::string& type,
                         const Eigen::Vector3f& colour, float intensity) {
  std::string l = "{\"name\":" + quoted(name) + ",\"type\":\"" + type + "\",\"color\":" +
                  vec(colour) + ",\"intensity\":" + num(intensity);
  if (type == "spot") l += ",\"spot\":{\"innerConeAngle\":0.3,\"outerConeAngle\":0.7}";
  lights_.push_back(l + "}");
  return static_cast<int>(lights_.size()) - 1;
}

void GlbWriter::add_animation(const std::string& name, int node, const std::vector<float>& times,
                              const std::vector<Eigen::Vector3f>& translations,
                              const std::vector<Eigen::Vector4f>& rotations) {
  const std::size_t n = times.size();
  const int input = accessor(view(times.data(), n * 4, 0), 5126, n, "SCALAR",
                             ",\"min\":[" + num(times.front()) + "],\"max\":[" + num(times.back()) + "]");
  const int t_out = accessor(view(translations.data(), n * 12, 0), 5126, n, "VEC3");
  const int r_out = accessor(view(rotations.data(), n * 16, 0), 5126, n, "VEC4");
  const std::string in = std::to_string(input);
  animations_.push_back(
      "{\"name\":" + quoted(name) + ",\"samplers\":[" +
      "{\"input\":" + in + ",\"output\":" + std::to_string(t_out) + ",\"interpolation\":\"LINEAR\"}," +
      "{\"input\":" + in + ",\"output\":" + std::to_string(r_out) + ",\"interpolation\":\"LINEAR\"}]," +
      "\"channels\":[{\"sampler\":0,\"target\":{\"node\":" + std::to_string(node) +
      ",\"path\":\"translation\"}},{\"sampler\":1,\"target\":{\"node\":" + std::to_string(node) +
      ",\"path\":\"rotation\"}}]}");
}

std::vector<std::uint8_t> GlbWriter::bytes() const {
  std::set<int> children;
  std::vector<std::string> nodes;
  for (const GltfNode& n : nodes_) {
    std::string s = "{\"name\":" + quoted(n.name) + ",\"translation\":" + vec(n.translation) +
                    ",\"rotation\":" + vec(n.rotation.coeffs());
    if (n.mesh >= 0) s += ",\"mesh\":" + std::to_string(n.mesh);
    if (!n.children.empty()) {
      std::vector<std::string> c;
      for (int k : n.children) {
        c.push_back(std::to_string(k));
        children.insert(k);
      }
      s += ",\"children\":" + join(c);
    }
    if (n.light >= 0)
      s += ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":" + std::to_string(n.light) + "}}";
    nodes.push_back(s + "}");
  }
  std::vector<std::string> roots;
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    if (!children.contains(static_cast<int>(i))) roots.push_back(std::to_string(i));

  std::string json = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"studio-scene-museum\"}";
  if (!lights_.empty())
    json += ",\"extensionsUsed\":[\"KHR_lights_punctual\"],\"extensions\":{\"KHR_lights_punctual\":{\"lights\":" +
            join(lights_) + "}}";
  json += ",\"scene\":0,\"scenes\":[{\"name\":\"museum\",\"nodes\":" + join(roots) + "}]";
  json += ",\"nodes\":" + join(nodes) + ",\"meshes\":" + join(meshes_) +
          ",\"materials\":" + join(materials_);
  if (!textures_.empty())
    json += ",\"samplers\":[{\"magFilter\":9729,\"minFilter\":9987,\"wrapS\":10497,\"wrapT\":10497}]"
            ",\"images\":" + join(images_) + ",\"textures\":" + join(textures_);
  if (!animations_.empty()) json += ",\"animations\":" + join(animations_);
  json += ",\"accessors\":" + join(accessors_) + ",\"bufferViews\":" + join(views_) +
          ",\"buffers\":[{\"byteLength\":" + std::to_string(bin_.size()) + "}]}";
  while (json.size() % 4) json += ' ';
  std::vector<std::uint8_t> bin = bin_;
  while (bin.size() % 4) bin.push_back(0);

  std::vector<std::uint8_t> out;
  put_u32(out, 0x46546C67);  // "glTF"
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  put_u32(out, static_cast<std::uint32_t>(json.size()));
  put_u32(out, 0x4E4F534A);  // "JSON"
  out.insert(out.end(), json.begin(), json.end());
  put_u32(out, static_cast<std::uint32_t>(bin.size()));
  put_u32(out, 0x004E4942);  // "BIN\0"
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

}  // namespace studio::scene_tools

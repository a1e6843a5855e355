#include "offline/frame_files.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace studio::offline {
namespace {

uint64_t fnv1a64(std::span<const uint8_t> bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (uint8_t b : bytes) h = (h ^ b) * 0x100000001b3ull;
  return h;
}

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
}
uint32_t get_u32(std::span<const uint8_t> b, std::size_t at) {
  return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 |
         uint32_t(b[at + 3]) << 24;
}
template <class T>
void append(std::vector<uint8_t>& bin, const T* data, std::size_t count) {
  const auto* p = reinterpret_cast<const uint8_t*>(data);
  bin.insert(bin.end(), p, p + count * sizeof(T));
}
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
std::string vec3(const Eigen::Vector3f& v) {
  return "[" + num(v.x()) + "," + num(v.y()) + "," + num(v.z()) + "]";
}

// The byte offsets of the sections in the BIN chunk (see the header).
struct Sections {
  std::size_t positions, normals, colours, indices, total;
};
Sections sections(std::size_t nv, std::size_t nt, bool coloured) {
  Sections s;
  s.positions = 0;
  s.normals = 12 * nv;
  s.colours = 24 * nv;
  s.indices = s.colours + (coloured ? 12 * nv : 0);
  s.total = s.indices + 12 * nt;
  return s;
}

// buffer views and accessors of one frame's mesh into buffer `buffer` at `base` (file offset of
// the BIN data for the index, 0 inside the frame file); appends to the JSON arrays and returns
// the primitive's JSON.
std::string mesh_json(int buffer, std::size_t base, const FrameFileInfo& f, std::string& views,
                      std::string& accessors, int& view_count, int& accessor_count) {
  const Sections s = sections(f.vertices, f.triangles, f.coloured);
  const auto add = [&](std::size_t offset, std::size_t length, int target, int component,
                       std::size_t count, const char* type, const std::string& extra) {
    if (!views.empty()) views += ",";
    views += "{\"buffer\":" + std::to_string(buffer) +
             ",\"byteOffset\":" + std::to_string(base + offset) +
             ",\"byteLength\":" + std::to_string(length) + ",\"target\":" + std::to_string(target) +
             "}";
    if (!accessors.empty()) accessors += ",";
    accessors += "{\"bufferView\":" + std::to_string(view_count++) +
                 ",\"componentType\":" + std::to_string(component) +
                 ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"" + extra + "}";
    return accessor_count++;
  };
  const int pos = add(s.positions, 12 * f.vertices, 34962, 5126, f.vertices, "VEC3",
                      ",\"min\":" + vec3(f.min) + ",\"max\":" + vec3(f.max));
  const int nrm = add(s.normals, 12 * f.vertices, 34962, 5126, f.vertices, "VEC3", "");
  std::string attributes =
      "\"POSITION\":" + std::to_string(pos) + ",\"NORMAL\":" + std::to_string(nrm);
  if (f.coloured) {
    const int col = add(s.colours, 12 * f.vertices, 34962, 5126, f.vertices, "VEC3", "");
    attributes += ",\"COLOR_0\":" + std::to_string(col);
  }
  const int idx = add(s.indices, 12 * f.triangles, 34963, 5125, 3 * f.triangles, "SCALAR", "");
  return "{\"attributes\":{" + attributes + "},\"indices\":" + std::to_string(idx) +
         ",\"material\":0}";
}

const char* kMaterial =
    "\"materials\":[{\"name\":\"actor\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],"
    "\"metallicFactor\":0,\"roughnessFactor\":1}}]";

// sRGB display value (0..255) to linear (glTF COLOR_0 is linear).
float linear(float display) {
  const float c = std::clamp(display / 255.0f, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// The number after "key": in the JSON text (our own writer's), or -1.
long long json_integer(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const auto at = json.find(k);
  if (at == std::string::npos) return -1;
  return std::strtoll(json.c_str() + at + k.size(), nullptr, 10);
}

std::string base64(std::span<const uint8_t> b) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const uint32_t v = uint32_t(b[i]) << 16 | (i + 1 < b.size() ? uint32_t(b[i + 1]) << 8 : 0) |
                       (i + 2 < b.size() ? uint32_t(b[i + 2]) : 0);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < b.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < b.size() ? t[v & 63] : '=';
  }
  return out;
}

}  // namespace

std::string frame_file_name(const std::string& name, int64_t frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%06lld.glb", static_cast<long long>(frame));
  return name + buf;
}
std::string index_file_name(const std::string& name) { return name + ".gltf"; }

std::string fingerprint(std::string_view text) {
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(
                    fnv1a64({reinterpret_cast<const uint8_t*>(text.data()), text.size()})));
  return hash;
}

// The option tag is kept to JSON-safe characters.
std::string safe_tag(const std::string& t) {
  std::string out;
  for (char c : t) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') out += c;
  }
  return out;
}

std::vector<uint8_t> encode_frame_glb(const hull::Mesh& mesh,
                                      const std::vector<Eigen::Vector3f>* colours,
                                      const std::string& name, int64_t frame,
                                      const std::string& options) {
  FrameFileInfo f;
  f.frame = frame;
  f.vertices = mesh.vertices.size();
  f.triangles = mesh.triangles.size();
  f.coloured = colours != nullptr;
  if (!mesh.vertices.empty()) {
    f.min = f.max = mesh.vertices.front();
    for (const auto& v : mesh.vertices) f.min = f.min.cwiseMin(v), f.max = f.max.cwiseMax(v);
  }
  std::vector<uint8_t> bin;
  append(bin, mesh.vertices.data(), mesh.vertices.size());
  std::vector<Eigen::Vector3f> normals = mesh.normals;
  normals.resize(mesh.vertices.size(), Eigen::Vector3f::UnitY());
  append(bin, normals.data(), normals.size());
  if (colours) {
    std::vector<Eigen::Vector3f> lin(mesh.vertices.size(), Eigen::Vector3f::Constant(0.5f));
    for (std::size_t n = 0; n < lin.size() && n < colours->size(); ++n) {
      lin[n] = Eigen::Vector3f(linear((*colours)[n].x()), linear((*colours)[n].y()),
                               linear((*colours)[n].z()));
    }
    append(bin, lin.data(), lin.size());
  }
  append(bin, mesh.triangles.data(), mesh.triangles.size());
  std::string views, accessors;
  int nview = 0, nacc = 0;
  const std::string primitive = mesh_json(0, 0, f, views, accessors, nview, nacc);
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a64(bin)));
  std::string json =
      "{\"asset\":{\"version\":\"2.0\",\"generator\":\"studio-hull offline\"},\"scene\":0,"
      "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"name\":\"" +
      name +
      "\",\"mesh\":0}],"
      "\"meshes\":[{\"name\":\"" +
      name + "\",\"primitives\":[" + primitive + "]}]," + kMaterial +
      ",\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) + "}],\"bufferViews\":[" +
      views + "],\"accessors\":[" + accessors +
      "],\"extras\":{\"studio_frame\":" + std::to_string(frame) +
      ",\"studio_vertices\":" + std::to_string(f.vertices) +
      ",\"studio_triangles\":" + std::to_string(f.triangles) +
      ",\"studio_coloured\":" + (f.coloured ? "1" : "0") + ",\"studio_options\":\"" +
      safe_tag(options) + "\",\"studio_bin_fnv1a64\":\"" + hash + "\"}}";
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::vector<uint8_t> out;
  put_u32(out, 0x46546C67);  // "glTF"
  put_u32(out, 2);
  put_u32(out, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  put_u32(out, uint32_t(json.size()));
  put_u32(out, 0x4E4F534A);  // "JSON"
  out.insert(out.end(), json.begin(), json.end());
  put_u32(out, uint32_t(bin.size()));
  put_u32(out, 0x004E4942);  // "BIN\0"
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

Expected<FrameFileInfo> verify_frame_glb(std::span<const uint8_t> b) {
  if (b.size() < 28 || get_u32(b, 0) != 0x46546C67 || get_u32(b, 4) != 2)
    return fail("not a glTF 2.0 binary");
  if (get_u32(b, 8) != b.size())
    return fail("length " + std::to_string(get_u32(b, 8)) + " in the header, file has " +
                std::to_string(b.size()) + " bytes (truncated?)");
  const std::size_t json_len = get_u32(b, 12);
  if (get_u32(b, 16) != 0x4E4F534A || 20 + json_len + 8 > b.size())
    return fail("malformed JSON chunk");
  const std::string json(reinterpret_cast<const char*>(b.data() + 20), json_len);
  const std::size_t bin_at = 20 + json_len;
  const std::size_t bin_len = get_u32(b, bin_at);
  if (get_u32(b, bin_at + 4) != 0x004E4942 || bin_at + 8 + bin_len != b.size())
    return fail("malformed BIN chunk");
  FrameFileInfo f;
  const long long frame = json_integer(json, "studio_frame"),
                  nv = json_integer(json, "studio_vertices"),
                  nt = json_integer(json, "studio_triangles"),
                  col = json_integer(json, "studio_coloured");
  if (frame < 0 || nv < 0 || nt < 0 || col < 0)
    return fail("not a studio-hull offline frame file (no extras)");
  f.frame = frame, f.vertices = std::size_t(nv), f.triangles = std::size_t(nt),
  f.coloured = col == 1;
  f.file_size = b.size();
  f.bin_offset = bin_at + 8;
  const Sections s = sections(f.vertices, f.triangles, f.coloured);
  if (s.total > bin_len || bin_len > s.total + 3) return fail("BIN size does not match the counts");
  const std::string key = "\"studio_bin_fnv1a64\":\"";
  const auto at = json.find(key);
  if (at == std::string::npos) return fail("no hash in the extras");
  char hash[20];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(
                    fnv1a64(b.subspan(f.bin_offset, s.total + (bin_len - s.total)))));
  if (json.compare(at + key.size(), 16, hash) != 0) return fail("hash mismatch (damaged file)");
  const std::string opt_key = "\"studio_options\":\"";
  if (const auto o = json.find(opt_key); o != std::string::npos) {
    const auto end = json.find('"', o + opt_key.size());
    if (end == std::string::npos) return fail("malformed extras");
    f.options = json.substr(o + opt_key.size(), end - o - opt_key.size());
  }
  for (std::size_t n = 0; n < f.vertices; ++n) {
    Eigen::Vector3f v;
    std::memcpy(v.data(), b.data() + f.bin_offset + 12 * n, 12);
    if (n == 0) f.min = f.max = v;
    f.min = f.min.cwiseMin(v), f.max = f.max.cwiseMax(v);
  }
  return f;
}

Expected<FrameFileInfo> verify_frame_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path + ": cannot open");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  auto f = verify_frame_glb(bytes);
  if (!f) return fail(path + ": " + f.error().message);
  return f;
}

Expected<void> write_file_atomic(const std::string& path, std::span<const uint8_t> bytes) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail(tmp + ": cannot write");
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.flush();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      return fail(tmp + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return fail(path + ": " + ec.message());
  return {};
}

std::string encode_index_gltf(const std::string& name, double fps,
                              const std::vector<FrameFileInfo>& frames) {
  std::string buffers, views, accessors, meshes, nodes, node_list, channels, samplers;
  int nview = 0, nacc = 0;
  // Key data (embedded buffer 0): per frame k, times and scales of its STEP keys.
  std::vector<uint8_t> keys;
  struct Keys {
    std::size_t time_at, scale_at;
    int count;
  };
  std::vector<Keys> per_frame;
  const double period = 1.0 / fps;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    std::vector<float> times, scales;
    const double t = double(k) * period;
    if (k > 0) times.push_back(0), scales.insert(scales.end(), {0, 0, 0});
    times.push_back(float(t)), scales.insert(scales.end(), {1, 1, 1});
    if (k + 1 < frames.size())
      times.push_back(float(t + period)), scales.insert(scales.end(), {0, 0, 0});
    Keys kk{keys.size(), 0, int(times.size())};
    append(keys, times.data(), times.size());
    kk.scale_at = keys.size();
    append(keys, scales.data(), scales.size());
    per_frame.push_back(kk);
  }
  buffers = "{\"byteLength\":" + std::to_string(keys.size()) +
            ",\"uri\":\"data:application/octet-stream;base64," + base64(keys) + "\"}";
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const FrameFileInfo& f = frames[k];
    const std::string file = frame_file_name(name, f.frame);
    buffers += ",{\"byteLength\":" + std::to_string(f.file_size) + ",\"uri\":\"" + file + "\"}";
    const std::string primitive =
        mesh_json(int(k) + 1, f.bin_offset, f, views, accessors, nview, nacc);
    const std::string stem = file.substr(0, file.size() - 4);
    if (k) meshes += ",", nodes += ",", node_list += ",", channels += ",", samplers += ",";
    meshes += "{\"name\":\"" + stem + "\",\"primitives\":[" + primitive + "]}";
    nodes += "{\"name\":\"" + stem + "\",\"mesh\":" + std::to_string(k) +
             ",\"scale\":" + (k == 0 ? "[1,1,1]" : "[0,0,0]") + "}";
    node_list += std::to_string(k);
    // The key accessors (buffer 0).
    const Keys& kk = per_frame[k];
    views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(kk.time_at) +
             ",\"byteLength\":" + std::to_string(4 * kk.count) + "}";
    float tmin = k > 0 ? 0.0f : 0.0f,
          tmax = float(double(std::min(k + 1, frames.size() - 1)) * period);
    if (k + 1 >= frames.size()) tmax = float(double(k) * period);
    accessors += ",{\"bufferView\":" + std::to_string(nview++) +
                 ",\"componentType\":5126,\"count\":" + std::to_string(kk.count) +
                 ",\"type\":\"SCALAR\",\"min\":[" + num(tmin) + "],\"max\":[" + num(tmax) + "]}";
    const int time_acc = nacc++;
    views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(kk.scale_at) +
             ",\"byteLength\":" + std::to_string(12 * kk.count) + "}";
    accessors += ",{\"bufferView\":" + std::to_string(nview++) +
                 ",\"componentType\":5126,\"count\":" + std::to_string(kk.count) +
                 ",\"type\":\"VEC3\"}";
    const int scale_acc = nacc++;
    samplers += "{\"input\":" + std::to_string(time_acc) +
                ",\"output\":" + std::to_string(scale_acc) + ",\"interpolation\":\"STEP\"}";
    channels += "{\"sampler\":" + std::to_string(k) + ",\"target\":{\"node\":" + std::to_string(k) +
                ",\"path\":\"scale\"}}";
  }
  std::string json =
      "{\"asset\":{\"version\":\"2.0\",\"generator\":\"studio-hull offline (index)\"},"
      "\"scene\":0,\"scenes\":[{\"name\":\"" +
      name + "\",\"nodes\":[" + node_list +
      "]}],"
      "\"nodes\":[" +
      nodes + "],\"meshes\":[" + meshes + "]," + kMaterial + ",\"buffers\":[" + buffers +
      "],\"bufferViews\":[" + views + "],\"accessors\":[" + accessors + "]";
  if (!frames.empty()) {
    json += ",\"animations\":[{\"name\":\"" + name + "\",\"channels\":[" + channels +
            "],\"samplers\":[" + samplers + "]}]";
  }
  json += ",\"extras\":{\"studio_fps\":" + num(fps) +
          ",\"studio_frames\":" + std::to_string(frames.size()) + "}}\n";
  return json;
}

}  // namespace studio::offline

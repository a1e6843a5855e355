#include "hull/mesh_io.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace studio::hull {
namespace {

template <class T>
void put(std::vector<uint8_t>& out, const T& value) {
  const auto* p = reinterpret_cast<const uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

void put_bytes(std::vector<uint8_t>& out, const void* data, std::size_t n) {
  const auto* p = static_cast<const uint8_t*>(data);
  out.insert(out.end(), p, p + n);
}

bool ends_with(const std::string& s, const char* suffix) {
  const std::size_t n = std::strlen(suffix);
  if (s.size() < n) return false;
  for (std::size_t k = 0; k < n; ++k) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - n + k])) != suffix[k]) return false;
  }
  return true;
}

}  // namespace

Expected<MeshFormat> mesh_format_from_path(const std::string& path) {
  if (ends_with(path, ".ply")) return MeshFormat::ply;
  if (ends_with(path, ".obj")) return MeshFormat::obj;
  if (ends_with(path, ".glb")) return MeshFormat::glb;
  return fail(path + ": unknown mesh format (use .ply, .obj or .glb)");
}

std::vector<uint8_t> encode_ply(const Mesh& mesh) {
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment studio visual hull\n"
    << "element vertex " << mesh.vertices.size() << "\n"
    << "property float x\nproperty float y\nproperty float z\n"
    << "property float nx\nproperty float ny\nproperty float nz\n"
    << "element face " << mesh.triangles.size() << "\n"
    << "property list uchar int vertex_indices\nend_header\n";
  const std::string header = h.str();
  std::vector<uint8_t> out(header.begin(), header.end());
  out.reserve(out.size() + mesh.vertices.size() * 24 + mesh.triangles.size() * 13);
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    put_bytes(out, mesh.vertices[k].data(), 12);
    put_bytes(out, mesh.normals[k].data(), 12);
  }
  for (const auto& t : mesh.triangles) {
    put(out, uint8_t(3));
    for (uint32_t i : t) put(out, int32_t(i));
  }
  return out;
}

std::string encode_obj(const Mesh& mesh) {
  std::string out = "# studio visual hull\n";
  char line[128];
  for (const auto& v : mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", v.x(), v.y(), v.z());
    out += line;
  }
  for (const auto& n : mesh.normals) {
    std::snprintf(line, sizeof line, "vn %.6g %.6g %.6g\n", n.x(), n.y(), n.z());
    out += line;
  }
  for (const auto& t : mesh.triangles) {
    std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", t[0] + 1, t[0] + 1, t[1] + 1,
                  t[1] + 1, t[2] + 1, t[2] + 1);
    out += line;
  }
  return out;
}

std::vector<uint8_t> encode_glb(const Mesh& mesh) {
  const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
  if (nv) {
    lo = hi = mesh.vertices[0];
    for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  }
  // Binary chunk: positions, normals, indices (each a multiple of 4 bytes).
  std::vector<uint8_t> bin;
  for (const auto& v : mesh.vertices) put_bytes(bin, v.data(), 12);
  for (const auto& n : mesh.normals) put_bytes(bin, n.data(), 12);
  for (const auto& t : mesh.triangles) put_bytes(bin, t.data(), 12);
  std::ostringstream j;
  j.precision(9);
  j << R"({"asset":{"version":"2.0","generator":"studio hull"},"scene":0,"scenes":[{"nodes":[0]}],)"
    << R"("nodes":[{"mesh":0,"name":"actor"}],)"
    << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2,"mode":4}]}],)"
    << R"("buffers":[{"byteLength":)" << bin.size() << "}],"
    << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << nv * 12
    << R"(,"target":34962},{"buffer":0,"byteOffset":)" << nv * 12 << R"(,"byteLength":)" << nv * 12
    << R"(,"target":34962},{"buffer":0,"byteOffset":)" << nv * 24 << R"(,"byteLength":)" << nt * 12
    << R"(,"target":34963}],)"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << nv
    << R"(,"type":"VEC3","min":[)" << lo.x() << "," << lo.y() << "," << lo.z() << "],\"max\":["
    << hi.x() << "," << hi.y() << "," << hi.z() << "]},"
    << R"({"bufferView":1,"componentType":5126,"count":)" << nv << R"(,"type":"VEC3"},)"
    << R"({"bufferView":2,"componentType":5125,"count":)" << nt * 3 << R"(,"type":"SCALAR"}]})";
  std::string json = j.str();
  while (json.size() % 4) json += ' ';
  std::vector<uint8_t> out;
  put(out, uint32_t(0x46546C67));  // "glTF"
  put(out, uint32_t(2));
  put(out, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  put(out, uint32_t(json.size()));
  put(out, uint32_t(0x4E4F534A));  // "JSON"
  put_bytes(out, json.data(), json.size());
  put(out, uint32_t(bin.size()));
  put(out, uint32_t(0x004E4942));  // "BIN\0"
  put_bytes(out, bin.data(), bin.size());
  return out;
}

Expected<void> write_mesh(const Mesh& mesh, const std::string& path, MeshFormat format) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return fail(path + ": cannot open for writing");
  if (format == MeshFormat::obj) {
    const std::string s = encode_obj(mesh);
    f.write(s.data(), std::streamsize(s.size()));
  } else {
    const std::vector<uint8_t> b = format == MeshFormat::ply ? encode_ply(mesh) : encode_glb(mesh);
    f.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
  }
  f.close();
  if (!f) return fail(path + ": write failed");
  return {};
}

Expected<void> write_mesh(const Mesh& mesh, const std::string& path) {
  auto format = mesh_format_from_path(path);
  if (!format) return std::unexpected(format.error());
  return write_mesh(mesh, path, *format);
}

}  // namespace studio::hull

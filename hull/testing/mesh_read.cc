#include "testing/mesh_read.h"

#include <fstream>
#include <sstream>

namespace studio::hull::testing {

Expected<Mesh> read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return fail(path + ": cannot open");
  std::string line;
  std::size_t vertices = 0, faces = 0;
  bool binary = false;
  while (std::getline(f, line) && line != "end_header") {
    std::istringstream s(line);
    std::string word, what;
    s >> word;
    if (word == "format") binary = line == "format binary_little_endian 1.0";
    if (word == "element") {
      std::size_t n = 0;
      if (!(s >> what >> n)) return fail(path + ": bad header line '" + line + "'");
      (what == "vertex" ? vertices : faces) = n;
    }
  }
  if (!binary || line != "end_header") return fail(path + ": not a binary little-endian PLY");
  Mesh m;
  m.vertices.resize(vertices);
  m.normals.resize(vertices);
  for (std::size_t k = 0; k < vertices; ++k) {
    f.read(reinterpret_cast<char*>(m.vertices[k].data()), 12);
    f.read(reinterpret_cast<char*>(m.normals[k].data()), 12);
  }
  m.triangles.resize(faces);
  for (std::size_t k = 0; k < faces; ++k) {
    unsigned char n = 0;
    int32_t idx[3];
    f.read(reinterpret_cast<char*>(&n), 1);
    f.read(reinterpret_cast<char*>(idx), 12);
    if (n != 3) return fail(path + ": face " + std::to_string(k) + " is not a triangle");
    for (int i = 0; i < 3; ++i) {
      if (idx[i] < 0 || std::size_t(idx[i]) >= vertices) return fail(path + ": bad vertex index");
      m.triangles[k][i] = uint32_t(idx[i]);
    }
  }
  if (!f) return fail(path + ": truncated");
  return m;
}

}  // namespace studio::hull::testing

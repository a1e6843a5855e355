#pragma once
// Mesh writers (DESIGN §4): PLY (binary little-endian, float positions and normals, int
// triangles), Wavefront OBJ (v / vn / f a//a) and glTF 2.0 binary (.glb: one mesh, POSITION and
// NORMAL float accessors, uint32 indices). Errors name the file.

#include <string>
#include <vector>

#include "core/error.h"
#include "hull/segment_mesh.h"

namespace studio::hull {

enum class MeshFormat { ply, obj, glb };

// From a file name's extension (.ply, .obj, .glb); fails on anything else.
Expected<MeshFormat> mesh_format_from_path(const std::string& path);

std::vector<uint8_t> encode_ply(const Mesh& mesh);
std::string encode_obj(const Mesh& mesh);
std::vector<uint8_t> encode_glb(const Mesh& mesh);

Expected<void> write_mesh(const Mesh& mesh, const std::string& path, MeshFormat format);
Expected<void> write_mesh(const Mesh& mesh, const std::string& path);  // format from extension

}  // namespace studio::hull

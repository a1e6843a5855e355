#pragma once
// Reads back the binary PLY that hull/mesh_io.h writes (float x y z nx ny nz, uchar-int faces),
// for tests that run the CLI as a process and check its meshes. Not part of the library; not a
// general PLY reader (any other layout is an error).

#include <string>

#include "core/error.h"
#include "hull/segment_mesh.h"

namespace studio::hull::testing {

Expected<Mesh> read_ply(const std::string& path);

}  // namespace studio::hull::testing

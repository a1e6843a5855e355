#pragma once
// The files of an offline sequence (issue 21): one self-verifying glTF binary per frame and an
// index that DCC tools load as one animated object.
//
// Naming (Blender's and Unreal's sequence importers group trailing digit runs):
//   <name>_<frame, 6 digits>.glb   e.g. actor_000123.glb, one node and mesh named the same
//   <name>.gltf                    the index
//
// Frame file: glTF 2.0 binary, one mesh (POSITION, NORMAL, optional COLOR_0 as linear float RGB,
// uint32 indices), one material (white, rough, non-metallic, so the vertex colour shows).
// Layout of the BIN chunk, in this order, each 4-byte aligned: positions, normals, colours,
// indices. The JSON's "extras" hold the frame number, the counts and an FNV-1a 64 hash of the BIN
// chunk, so a frame can be verified without any other file (verify_frame_glb). The bytes depend
// only on the mesh, the colours, the name and the frame: a rerun writes identical files.
//
// Index: a glTF 2.0 JSON file whose buffers are the frame files themselves (a buffer may be any
// file; the buffer views point into each frame's BIN chunk, so nothing is copied), one node per
// frame, and one animation that shows each frame's node (scale 1) exactly during its frame period
// at `fps` (STEP keys; scale 0 otherwise): a flip-book that Blender's glTF importer plays as one
// animated object. Its own key data is an embedded base64 buffer.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "hull/segment_mesh.h"

namespace studio::offline {

std::string frame_file_name(const std::string& name, int64_t frame);  // name_000123.glb
std::string index_file_name(const std::string& name);                 // name.gltf

// colours: display RGB 0..255 per vertex (texture.h), or null for an untextured mesh.
// options: a fingerprint of what made the frame (fingerprint() of the settings), stored in the
// extras so that a rerun with other settings recomputes the frame instead of skipping it.
std::vector<uint8_t> encode_frame_glb(const hull::Mesh& mesh,
                                      const std::vector<Eigen::Vector3f>* colours,
                                      const std::string& name, int64_t frame,
                                      const std::string& options = "");

// 16 hex digits (FNV-1a 64) of a text.
std::string fingerprint(std::string_view text);

struct FrameFileInfo {
  int64_t frame = 0;
  std::size_t vertices = 0, triangles = 0;
  bool coloured = false;
  std::size_t file_size = 0;
  std::size_t bin_offset = 0;  // file offset of the BIN chunk's data
  Eigen::Vector3f min = Eigen::Vector3f::Zero(), max = Eigen::Vector3f::Zero();
  std::string options;  // as given to encode_frame_glb
};

// Checks a frame file's structure (header, chunk sizes, counts against the BIN size) and its
// hash; fails with one line on anything else (a truncated or foreign file).
Expected<FrameFileInfo> verify_frame_glb(std::span<const uint8_t> bytes);
Expected<FrameFileInfo> verify_frame_file(const std::string& path);

// Writes through `path`.tmp.<pid> and a rename: a killed writer leaves no partial `path`.
Expected<void> write_file_atomic(const std::string& path, std::span<const uint8_t> bytes);

// The index over the given frames (files in the index's folder, ordered by frame).
std::string encode_index_gltf(const std::string& name, double fps,
                              const std::vector<FrameFileInfo>& frames);

}  // namespace studio::offline

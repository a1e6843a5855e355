#pragma once
// Assets are named by path and content hash: SHA-256 of the file's bytes as 64 lowercase hex
// digits (OpenSSL's implementation). A renderer compares the hash a SceneNode names with the
// hash of the file it has, and reports a missing or different asset.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"

namespace studio::scene_assets {

std::string sha256_hex(const std::uint8_t* data, std::size_t size);
// Error: the file cannot be read ("set.glb: No such file or directory").
Expected<std::string> sha256_file(const std::string& path);

}  // namespace studio::scene_assets

#pragma once
// The full state of a Scene as bytes, for persistence (the server writes them atomically and
// resumes from them after a crash) and for the state hash. Little-endian, doubles bit-exact,
// versioned:
//   "STSCENE1", options, frame, nodes (by id), animations (by name) with their clocks.
// deserialize() checks every length against the remaining bytes, every enum and number, and the
// scene invariants, so corrupt or truncated bytes give an error, never a crash or a half scene.

#include <cstdint>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace studio::scene {

std::vector<std::uint8_t> serialize(const Scene& scene);
Expected<Scene> deserialize(const std::vector<std::uint8_t>& bytes);

// 64-bit FNV-1a of bytes (the state hash's function).
std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size);

}  // namespace studio::scene

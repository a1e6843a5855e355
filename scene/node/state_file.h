#pragma once
// The scene server's persisted state (state_dir/scene.state): the whole scene (scene::serialize:
// nodes, animations and their clocks, the frame of the last tick) and the ids of the nodes that
// were on the wire (written as alive SceneNode instances and not yet disposed) when it was
// written.
//
// The published ids make a restart clean after kill -9: the server persists BEFORE it publishes
// (write-ahead), so every node a reader may hold is either in the scene or in `published`; on
// start it re-publishes the scene and disposes every published id the scene no longer has (a
// removal whose dispose never went out, or a node taken out of the state while it was down).
//
// File: "STSRVST1", u32 id count, (u32 length, bytes) per id, u64 length + scene bytes, u64
// FNV-1a of everything before it; little-endian. Written atomically: scene.state.tmp is written,
// fsync'd, renamed over scene.state, and the directory fsync'd, so a crash leaves the old or the
// new file, never a mix.

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace studio::scene::node {

struct PersistedState {
  Scene scene;
  std::set<NodeId> published;
};

std::vector<std::uint8_t> encode_state(const Scene& scene, const std::set<NodeId>& published);
Expected<PersistedState> decode_state(const std::vector<std::uint8_t>& bytes);

// Path of the state file in `dir`.
std::string state_path(const std::string& dir);

// Writes the state atomically into `dir` (created if missing).
Expected<void> write_state(const std::string& dir, const Scene& scene,
                           const std::set<NodeId>& published);
// nullopt when there is no state file; an error naming the file for an unreadable or corrupt one.
Expected<std::optional<PersistedState>> read_state(const std::string& dir);

}  // namespace studio::scene::node

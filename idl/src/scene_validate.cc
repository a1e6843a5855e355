// Validators of the scene topics (wire/types.h): SceneNode, SceneCommand, SceneState. They check
// the structure a sample must have before it reaches the scene library: terminated strings,
// enum ranges, finite numbers, sequence lengths consistent with each other. Meaning (does the
// node exist, is the quaternion of unit length after normalising, is the colour in [0, 1]) is the
// library's job: scene::Scene::apply refuses it with a one-line error, which the server counts.

#include <cmath>
#include <cstring>

#include "wire/sample.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

constexpr uint32_t kKnownNodeFlags = studio_SCENE_NODE_VISIBLE | studio_SCENE_NODE_ACTOR |
                                     studio_SCENE_NODE_CAST_SHADOW |
                                     studio_SCENE_NODE_HIGH_CONTRAST;
constexpr uint32_t kMaxMeshes = 1024;
constexpr uint32_t kMaxTracks = 1024;
constexpr uint32_t kMaxKeys = 1u << 20;

template <std::size_t N>
bool text_ok(const char (&s)[N]) {  // may be empty, must be terminated
  return std::memchr(s, 0, N) != nullptr;
}
template <class T, std::size_t N>
bool finite(const T (&v)[N]) {
  for (T x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
bool finite(std::span<const double> v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
template <class E>
uint32_t raw(const E& e) {  // enums off the wire as integers (an out-of-range C enum is UB)
  static_assert(sizeof(E) == sizeof(uint32_t));
  uint32_t v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

// The node payload, as published or as carried by a command (`published`: the topic's own
// rules on top: a non-empty id, not its own parent, a rigid 4x4 with last row 0 0 0 1).
Verdict check_node(const studio_SceneNode& s, bool published) {
  if (!text_ok(s.node_id) || !text_ok(s.parent) || !text_ok(s.asset) || !text_ok(s.material) ||
      !text_ok(s.texture) || !text_ok(s.asset_sha256) || !text_ok(s.actor_id))
    return Reject::bad_id;
  if (published && s.node_id[0] == '\0') return Reject::bad_id;
  if (published && std::strcmp(s.parent, s.node_id) == 0) return Reject::out_of_range;
  if (!finite(s.parent_from_node) || !finite(s.translation) || !finite(s.rotation) ||
      !finite(s.scale) || !finite(s.colour) || !finite(s.light_colour) ||
      !std::isfinite(s.light_intensity) || !std::isfinite(s.light_range) ||
      !std::isfinite(s.light_inner_cone) || !std::isfinite(s.light_outer_cone))
    return Reject::non_finite;
  if (published) {
    const double* m = s.parent_from_node;
    if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1) return Reject::out_of_range;
  }
  if (raw(s.kind) > studio_SCENE_KIND_ACTOR || raw(s.light_type) > studio_SCENE_LIGHT_SPOT)
    return Reject::out_of_range;
  if ((s.flags & ~kKnownNodeFlags) != 0) return Reject::out_of_range;
  if (view(s.asset_meshes).size() > kMaxMeshes) return Reject::bad_size;
  return std::nullopt;
}

Verdict check_track(const studio_SceneTrack& t) {
  if (!text_ok(t.node)) return Reject::bad_id;
  if (t.path > 2 || t.interpolation > 1) return Reject::out_of_range;
  const auto times = view(t.times), values = view(t.values);
  if (times.size() > kMaxKeys || values.size() != 4 * times.size()) return Reject::bad_size;
  if (!finite(times) || !finite(values)) return Reject::non_finite;
  return std::nullopt;
}

}  // namespace

Verdict validate(const studio_SceneNode& s) { return check_node(s, true); }

Verdict validate(const studio_SceneCommand& s) {
  if (!text_ok(s.target) || !text_ok(s.path) || !text_ok(s.sender)) return Reject::bad_id;
  if (!std::isfinite(s.value) || !finite(s.transform)) return Reject::non_finite;
  if (s.at_frame < studio_SCENE_AT_NOW) return Reject::out_of_range;
  if (raw(s.mode) > studio_SCENE_MODE_PING_PONG) return Reject::out_of_range;
  if (auto v = check_node(s.node, false)) return v;
  const auto tracks = view(s.tracks);
  if (tracks.size() > kMaxTracks) return Reject::bad_size;
  for (const studio_SceneTrack& t : tracks)
    if (auto v = check_track(t)) return v;
  switch (raw(s.verb)) {
    case studio_SCENE_LOAD_SET:
      return s.path[0] ? Verdict{} : Reject::bad_id;
    case studio_SCENE_MOVE_NODE:
    case studio_SCENE_REMOVE_NODE:
      return s.target[0] ? Verdict{} : Reject::bad_id;
    case studio_SCENE_PLAY:
    case studio_SCENE_PAUSE:
    case studio_SCENE_SEEK:
    case studio_SCENE_SPEED:  // negative plays backwards; |speed| <= 1000 is the library's rule
    case studio_SCENE_ADD_NODE:
    case studio_SCENE_SET_TRANSFORM:
    case studio_SCENE_SET_PARENT:
    case studio_SCENE_SET_MATERIAL:
    case studio_SCENE_SET_VISIBLE:
    case studio_SCENE_ADD_ANIMATION:
    case studio_SCENE_REMOVE_ANIMATION:
    case studio_SCENE_TICK:
      return std::nullopt;
  }
  return Reject::out_of_range;
}

Verdict validate(const studio_SceneState& s) {
  if (!text_ok(s.instance) || s.instance[0] == '\0') return Reject::bad_id;
  if (!text_ok(s.last_sender) || !text_ok(s.last_error)) return Reject::bad_id;
  return std::nullopt;
}

}  // namespace studio::wire

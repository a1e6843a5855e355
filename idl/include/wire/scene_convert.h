#pragma once
// Conversions between the scene topics (SceneNode, SceneCommand) and the scene library's types
// (scene/node.h, scene/command.h). Exact both ways: the local transform travels as TRS doubles,
// colours and light numbers as the floats the library holds, so a reader rebuilds exactly the
// node the server has (tests compare them with ==).
//
// Library studio_scene_wire (idl/CMakeLists.txt): the wire layer plus studio_scene, for the scene
// server and every reader of studio/scene/node (projector, preview, studioctl).

#include <cstdint>

#include "core/error.h"
#include "scene/command.h"
#include "scene/node.h"
#include "studio.h"

namespace studio::wire {

// scene::Node → SceneNode: every field (frame = node.frame, parent_from_node = local.matrix(),
// flags VISIBLE / ACTOR / HIGH_CONTRAST). capture_ns is the caller's. Error when a string is
// longer than its IDL bound (ids 63, paths 255 characters).
Expected<void> from_core(const scene::Node& node, studio_SceneNode& sample);
// SceneNode → scene::Node (frame = sample.frame). Structure only: Scene::apply (or
// Node::validate) judges the content.
Expected<scene::Node> to_core(const studio_SceneNode& sample);

// SceneCommand → scene::Command. at_frame SCENE_AT_NOW becomes `now_frame`. MOVE_NODE's 4x4 is
// decomposed into TRS (no shear: columns give the scale, the orthonormalised rest the rotation).
// SCENE_LOAD_SET is not a library command (the server loads the file and applies the result as
// one Batch): error. ADD_ANIMATION with mode KEEP: error.
Expected<scene::Command> to_core(const studio_SceneCommand& sample, std::int64_t now_frame);
// scene::Command → SceneCommand payload (verb, target, node, tracks, at_frame = command.frame;
// sender, command_id, frame and capture_ns are the caller's). A Batch has no wire form: error.
Expected<void> from_core(const scene::Command& command, studio_SceneCommand& sample);

}  // namespace studio::wire

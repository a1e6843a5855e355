#pragma once
// The scene server node (issue 14 item 3; TCSVT 2004 §V: the virtual scene server holds the
// master copy of the scene and distributes every change). A thin layer over scene::Scene on
// runtime::ServiceLoop:
//
//   studio/scene/command (SceneCommand) → wire::to_core → Scene::apply (all or nothing)
//   its own Tick every studio frame (clock.source studio) → Scene::apply(Tick{frame})
//   Scene::take_changes() → studio/scene/node: each added or changed node written as its keyed
//                           instance (reliable, transient-local, keep-last 1: a late reader gets
//                           the whole scene), each removed node disposed
//   studio/scene/state   → hash, node and animation counts, accepted / rejected / lost commands,
//                           the last rejection's error (reliable, transient-local)
//
// Order per loop wake: every command taken is applied; then, if any was accepted, the state is
// persisted (state_dir, atomically) BEFORE the changes are published, so no reader ever holds a
// node the persisted state does not know about (state_file.h); then the changes are published.
// Changes made by ticks alone are published at once and persisted every persist_interval.
// On start the persisted state is loaded (a corrupt file is a start error), the whole scene is
// published, and nodes the state says were published but are no longer in the scene are
// disposed.
//
// Rejections (counter `rejected`, the total, and `rejected_<reason>`): `malformed` (the
// SceneCommand validator, wire/types.h), `convert` (no library form: e.g. ADD_ANIMATION with
// mode KEEP), `load_set` (the scene file is missing or invalid), and the name of the refused
// library command (`add_node`, `set_transform`, `set_parent`, ...) with Scene::apply's error.
// Counters also: commands_in, commands_accepted, commands_lost (command_ids skipped in a
// sender's sequence less the malformed samples the validator dropped), ticks, nodes_published,
// nodes_disposed, persists, persist_failures.

#include <memory>

#include "runtime/service.h"
#include "scene_config.h"

namespace studio::scene::node {

// Builds the node (loads the persisted state) — exposed for tests that host it in-process.
Expected<std::unique_ptr<runtime::Node>> make_scene_server(NodeOptions options,
                                                           runtime::NodeContext& context);

// service_main's definition of the scene service (name "scene", binary studio-scene).
runtime::ServiceDefinition service_definition();

}  // namespace studio::scene::node

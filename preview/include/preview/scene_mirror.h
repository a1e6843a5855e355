#pragma once
// The preview's mirror of the scene graph (issue 16): the scene server publishes one keyed
// sample per node (studio/scene/node); the preview keeps the newest of each and rebuilds the
// scene from them when one changed.

#include <map>
#include <string>

#include "scene/scene.h"

namespace studio::preview {

// The scene of `nodes` (keyed by node id), parents before children: a node whose parent is not
// among them (not arrived yet, or disposed) is left out with its subtree until it is; an
// invalid node (scene::Scene::apply refuses it) likewise.
scene::Scene assemble_scene(const std::map<std::string, scene::Node>& nodes);

}  // namespace studio::preview

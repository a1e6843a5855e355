#pragma once
// The projector's scene in two layers (issue 15: render the scene only when it changes): the
// still layer, drawn into the cached static layer of the frame and reused while it is unchanged
// (projector_render::FrameRenderer::render(LayeredScene)), and the moving layer, drawn over it
// every frame. Which nodes move is the caller's knowledge (the projector node: nodes changed
// within the last SceneCacheOptions::settle_s); a moving node moves its whole subtree.
//
// Contract of split_scene:
// - still: every node not moving (with the same ids, parents, transforms; a node whose ancestor
//   moves is moving itself);
// - moving: every moving node, every light (the two layers are lit alike), and their ancestors
//   as plain groups (same transform and visibility, nothing drawn), so world transforms match;
// - a moving light changes the lighting of the still layer too: then nothing is split (still =
//   the whole scene, moving empty) and the still version changes with every change;
// - still_version: a hash of the still layer's nodes (equal nodes, equal version), so a change
//   of a moving node keeps it and any change of a still node changes it.

#include <cstdint>
#include <set>

#include "scene/scene.h"

namespace studio::projector {

struct SceneLayers {
  scene::Scene still;
  scene::Scene moving;
  std::uint64_t still_version = 0;
  std::size_t moving_nodes = 0;  // moving nodes in `moving` (groups and lights not counted)
  bool moving_light = false;     // a light moves: not split
};

SceneLayers split_scene(const scene::Scene& all, const std::set<scene::NodeId>& moving);

}  // namespace studio::projector

#pragma once
// Reading scene.yaml (the scene file) into a SceneDescription, through core/yaml's strict schema
// reader: unknown keys, wrong types, wrong list sizes and out-of-range numbers are one line
// naming file, line and key ("scene.yaml:7: nodes[0].colour: expected 4 numbers, got 3").
// Paths (set, asset, texture) are relative to the scene file's folder.
//
//   set: museum.glb               # glTF/GLB/OBJ virtual set (optional)
//   set_id: set                   # id of the set's root node; its nodes are set/<name>
//   fps: 25                       # studio frame rate: animation time per frame
//   view: {eye: [0, 4.5, 9.5], at: [0, 1, -6], fov: 60}   # default view of `studio-scene render`
//   high_contrast: [set/flyer]    # nodes drawn emissive (paper §V-F)
//   nodes:                        # extra nodes
//     - {id: actor, actor: actor0}
//     - {id: marker, asset: marker.obj, translation: [1, 0, 0], colour: [1, 0, 0, 1]}
//   animations:                   # extra keyframe animations
//     - name: spin
//       mode: loop                # once | loop | ping_pong
//       tracks:
//         - {node: marker, path: rotation, interpolation: linear, times: [0, 2],
//            values: [0, 0, 0, 1,  0, 1, 0, 0]}      # 3 numbers per key, 4 for rotation
//   play:                         # animations to start
//     - {animation: set/flight, at_frame: 0, mode: loop, speed: 1}

#include <string>

#include "core/error.h"
#include "scene_assets/scene_description.h"

namespace studio::scene_config {

Expected<scene_assets::SceneDescription> read_scene_file(const std::string& path);
Expected<scene_assets::SceneDescription> parse_scene_text(const std::string& text,
                                                          const std::string& name);

}  // namespace studio::scene_config

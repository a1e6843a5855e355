#pragma once
// Loading a scene file for the scene server: the initial scene (config key `scene`) and the
// SCENE_LOAD_SET command. `path` names a scene file (.yaml/.yml, scene_config/scene_yaml.h: the
// set, extra nodes, animations, what plays from which frame) or a set file (.glb, .gltf, .obj)
// alone, instantiated under the root id "set". The result is a whole new Scene built at studio
// frame `frame` (scene_assets::build_scene); its frame period must be the server's clock's, so a
// scene file whose `fps` disagrees is refused. Errors are one line naming the file.

#include <cstdint>
#include <string>

#include "core/error.h"
#include "scene/scene.h"
#include "scene_assets/instantiate.h"

namespace studio::scene::node {

Expected<Scene> load_scene_file(const std::string& path, const SceneOptions& clock,
                                std::int64_t frame, scene_assets::AssetCache& cache);

}  // namespace studio::scene::node

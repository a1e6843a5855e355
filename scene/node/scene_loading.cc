#include "scene_loading.h"

#include <filesystem>

#include "scene_assets/scene_description.h"
#include "scene_config/scene_yaml.h"

namespace studio::scene::node {

Expected<Scene> load_scene_file(const std::string& path, const SceneOptions& clock,
                                std::int64_t frame, scene_assets::AssetCache& cache) {
  const std::string ext = std::filesystem::path(path).extension().string();
  scene_assets::SceneDescription d;
  if (ext == ".yaml" || ext == ".yml") {
    auto read = scene_config::read_scene_file(path);
    if (!read) return std::unexpected(read.error());
    d = std::move(*read);
  } else {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return fail(path + ": no such set file");
    d.file = path;
    d.set = path;
    d.fps = 1.0 / clock.frame_period;
  }
  auto scene = scene_assets::build_scene(d, cache, frame);
  if (!scene) return std::unexpected(scene.error());
  if (!(scene->options() == clock))
    return fail(path + ": fps " + std::to_string(d.fps) + " differs from the server clock's " +
                std::to_string(1.0 / clock.frame_period));
  return scene;
}

}  // namespace studio::scene::node

#include "preview/scene_mirror.h"

#include <vector>

namespace studio::preview {

scene::Scene assemble_scene(const std::map<std::string, scene::Node>& nodes) {
  scene::Scene s;
  std::vector<const scene::Node*> pending;
  for (const auto& [id, n] : nodes) pending.push_back(&n);
  for (bool progress = true; progress && !pending.empty();) {
    progress = false;
    for (auto it = pending.begin(); it != pending.end();) {
      const scene::Node& n = **it;
      if (!n.parent.empty() && !s.find(n.parent)) {
        ++it;
        continue;
      }
      (void)s.apply({n.frame, scene::AddNode{n}});  // an invalid node is left out
      it = pending.erase(it);
      progress = true;
    }
  }
  return s;
}

}  // namespace studio::preview

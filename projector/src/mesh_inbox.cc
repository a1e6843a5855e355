#include "projector/mesh_inbox.h"

namespace studio::projector {

Expected<bool> MeshInbox::offer(const std::string& actor_id, std::uint64_t frame, ActorMesh mesh) {
  if (auto ok = mesh.validate(); !ok) return fail("actor " + actor_id + ": " + ok.error().message);
  if (auto it = last_capture_.find(actor_id);
      it != last_capture_.end() && mesh.capture_ns <= it->second)
    return fail("actor " + actor_id + ": mesh capture time not after the previous mesh's");
  last_capture_[actor_id] = mesh.capture_ns;
  auto [it, inserted] = waiting_.meshes.try_emplace(actor_id);
  it->second = Pending{frame, std::move(mesh)};
  return !inserted;
}

void MeshInbox::dispose(const std::string& actor_id) {
  waiting_.meshes.erase(actor_id);
  last_capture_.erase(actor_id);
  waiting_.removed.insert(actor_id);
}

MeshInbox::Taken MeshInbox::take() {
  Taken out;
  std::swap(out, waiting_);
  return out;
}

int apply(MeshInbox::Taken taken, MaskPlanner& planner, std::string* first_error) {
  for (const std::string& id : taken.removed) planner.remove(id);
  int refused = 0;
  for (auto& [id, p] : taken.meshes) {
    if (auto ok = planner.set_mesh(id, p.frame, std::move(p.mesh)); !ok) {
      if (refused++ == 0 && first_error != nullptr) *first_error = ok.error().message;
    }
  }
  return refused;
}

}  // namespace studio::projector

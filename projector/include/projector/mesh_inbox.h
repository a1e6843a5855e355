#pragma once
// Between the projector node's mesh handler and its render thread: the newest undrawn mesh of
// every actor. The handler offers each mesh as it arrives (checked here: valid, capture time
// after the actor's previous one); the render thread takes them all at the start of a frame and
// feeds them to its MaskPlanner (one motion estimate per mesh drawn). A mesh still waiting when
// a newer one of the same actor arrives is dropped — the projector always draws the newest — and
// the offer says so, for the node's meshes_superseded counter. Not thread-safe: the node guards it.

#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "core/error.h"
#include "projector/actor_mesh.h"
#include "projector/mask_planner.h"

namespace studio::projector {

class MeshInbox {
 public:
  struct Pending {
    std::uint64_t frame = 0;
    ActorMesh mesh;
  };
  struct Taken {
    std::set<std::string> removed;          // actors disposed (applied first, even when a
                                            // new mesh of theirs follows)
    std::map<std::string, Pending> meshes;  // then the newest mesh of each actor
  };

  // Ok(true): accepted and it replaced an undrawn mesh of that actor (dropped); Ok(false):
  // accepted. Errors (the mesh is refused, the previous one stays): invalid mesh, capture time not
  // after the actor's previous accepted mesh.
  Expected<bool> offer(const std::string& actor_id, std::uint64_t frame, ActorMesh mesh);
  // The actor left (disposed instance): its waiting mesh goes, and the planner drops it.
  void dispose(const std::string& actor_id);
  bool has_meshes() const { return !waiting_.meshes.empty(); }
  Taken take();

 private:
  Taken waiting_;
  std::map<std::string, std::int64_t> last_capture_;
};

// Applies what was taken to the planner: removals, then each mesh (its motion estimated there).
// Returns the number of meshes the planner refused (with the first message in *first_error).
int apply(MeshInbox::Taken taken, MaskPlanner& planner, std::string* first_error = nullptr);

}  // namespace studio::projector

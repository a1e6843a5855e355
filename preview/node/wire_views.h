#pragma once
// The preview node's conversions of wire samples into what it keeps (preview_node.h).
#include "preview_node.h"
#include "scene/actor_mesh.h"
#include "studio.h"

namespace studio::preview {

// ActorMesh sample → scene::ActorMesh (normals computed when the sample carries none).
scene::ActorMesh mesh_from_wire(const studio_ActorMesh& sample);
// CameraState sample → the camera panel's view of it.
CameraStateView state_from_wire(const studio_CameraState& sample);

}  // namespace studio::preview

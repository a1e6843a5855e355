#include "wire_views.h"

#include "wire/sample.h"

namespace studio::preview {

scene::ActorMesh mesh_from_wire(const studio_ActorMesh& s) {
  scene::ActorMesh m;
  m.actor_id = wire::str(s.actor_id);
  m.frame = int64_t(s.source_frame);
  const auto v = wire::view(s.vertices);
  const auto n = wire::view(s.normals);
  const auto t = wire::view(s.triangles);
  m.vertices.resize(v.size() / 3);
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    m.vertices[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  if (n.size() == v.size()) {
    m.normals.resize(m.vertices.size());
    for (std::size_t i = 0; i < m.normals.size(); ++i)
      m.normals[i] = {n[3 * i], n[3 * i + 1], n[3 * i + 2]};
  }
  m.triangles.resize(t.size() / 3);
  for (std::size_t i = 0; i < m.triangles.size(); ++i)
    m.triangles[i] = {t[3 * i], t[3 * i + 1], t[3 * i + 2]};
  if (m.normals.empty()) m.compute_normals();
  return m;
}

CameraStateView state_from_wire(const studio_CameraState& s) {
  CameraStateView v;
  v.camera_id = wire::str(s.camera_id);
  v.frame = s.frame;
  v.fps = s.fps;
  v.drops = s.drops;
  v.recording = s.recording;
  v.take = wire::str(s.take);
  v.error = wire::str(s.error);
  v.state = int(s.state);
  for (const auto& f : wire::view(s.features))
    v.features.push_back({std::string(wire::str(f.name)), f.value, f.min, f.max});
  return v;
}

}  // namespace studio::preview

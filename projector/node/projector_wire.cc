#include "projector_wire.h"

#include <algorithm>

#include "wire/convert.h"
#include "wire/sample.h"

namespace studio::projector {

ActorMesh mesh_of(const studio_ActorMesh& s) {
  ActorMesh m;
  auto v = wire::view(s.vertices);
  auto t = wire::view(s.triangles);
  m.vertices.reserve(v.size() / 3);
  for (std::size_t i = 0; i + 2 < v.size(); i += 3)
    m.vertices.emplace_back(v[i], v[i + 1], v[i + 2]);
  m.triangles.reserve(t.size() / 3);
  for (std::size_t i = 0; i + 2 < t.size(); i += 3)
    m.triangles.push_back({t[i], t[i + 1], t[i + 2]});
  m.capture_ns = s.capture_ns;
  return m;
}

void fill_frame(const FrameInfo& info, const projector_render::Readback& rb,
                studio_ProjectorFrame& f) {
  const MaskPlan* plan = info.plan;
  wire::set(f.projector_id, info.projector_id);
  f.frame = plan ? plan->newest_frame : 0;
  f.capture_ns = plan ? plan->newest_capture_ns : 0;
  f.render_frame = info.render_frame;
  f.render_done_ns = info.render_done_ns;
  f.latency_ms =
      f.capture_ns > 0 ? std::max(0.0, (info.render_done_ns - f.capture_ns) * 1e-6) : 0.0;
  f.margin_m = plan ? plan->margin.margin_m : 0.0;
  f.predicted = plan && plan->margin.predicted;
  f.actors = plan ? uint32_t(plan->masks.size()) : 0;
  for (int i = 0; i < 3; ++i) f.eye[i] = info.eye[i];
  f.two_pass = info.two_pass;
  wire::from_core(rb.blackout, f);
  f.thumb_width = uint32_t(rb.thumb_width);
  f.thumb_height = uint32_t(rb.thumb_height);
  wire::assign(f.thumbnail, rb.thumbnail);
}

}  // namespace studio::projector

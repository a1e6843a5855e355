#include "overlay_inputs.h"

#include <cmath>

#include "wire/convert.h"
#include "wire/sample.h"

namespace studio::preview {

OverlayInputs::OverlayInputs(runtime::ServiceLoop& loop, std::chrono::milliseconds head_timeout)
    : head_timeout_(head_timeout) {
  loop.input<studio_HeadPose>(
      {.received = "heads_in", .rate = false, .instance_changes = true},
      [this](const studio_HeadPose& s, const wire::SampleMeta& m) -> runtime::Outcome {
        const std::string id(wire::str(s.actor_id));
        std::lock_guard lock(mutex_);
        if (!m.valid_data) {
          if (m.disposed || !m.alive) heads_.erase(id);
          return {};
        }
        const Eigen::Vector3d p(s.position[0], s.position[1], s.position[2]);
        const Eigen::Vector3d v(s.velocity[0], s.velocity[1], s.velocity[2]);
        if (!p.allFinite() || !v.allFinite()) return runtime::reject("head", "not finite");
        heads_[id] = {{id, p, v, s.confidence}, std::chrono::steady_clock::now()};
        return {};
      });
  loop.input<studio_ProjectorCalibration>(
      {.received = "projector_calibrations_in", .rate = false},
      [this](const studio_ProjectorCalibration& s, const wire::SampleMeta&) -> runtime::Outcome {
        auto p = wire::to_core(s);
        if (!p) return runtime::reject("projector_calibration", p.error().message);
        std::lock_guard lock(mutex_);
        ProjectorView& v = projectors_[p->camera.id];
        v.projector = std::move(*p);
        v.calibrated = true;
        return {};
      });
  loop.input<studio_ProjectorFrame>(
      {.received = "projector_frames_in", .rate = false},
      [this](const studio_ProjectorFrame& s, const wire::SampleMeta&) -> runtime::Outcome {
        const auto thumb = wire::view(s.thumbnail);
        if (thumb.size() != std::size_t(s.thumb_width) * s.thumb_height * 3)
          return runtime::reject("thumbnail", "size does not match thumb_width x thumb_height");
        std::lock_guard lock(mutex_);
        ProjectorView& v = projectors_[std::string(wire::str(s.projector_id))];
        v.render_frame = s.render_frame;
        v.mesh_frame = s.frame;
        v.latency_ms = s.latency_ms;
        v.margin_m = s.margin_m;
        if (!thumb.empty()) {
          v.thumb_width = int(s.thumb_width);
          v.thumb_height = int(s.thumb_height);
          v.thumbnail.assign(thumb.begin(), thumb.end());
          ++v.thumbnail_version;
        }
        return {};
      });
}

std::vector<HeadMarker> OverlayInputs::heads() const {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  std::vector<HeadMarker> out;
  for (const auto& [id, h] : heads_)
    if (now - h.seen <= head_timeout_) out.push_back(h.marker);
  return out;
}

std::map<std::string, ProjectorView> OverlayInputs::projectors() const {
  std::lock_guard lock(mutex_);
  return projectors_;
}

std::vector<Projector> OverlayInputs::calibrated() const {
  std::lock_guard lock(mutex_);
  std::vector<Projector> out;
  for (const auto& [id, v] : projectors_)
    if (v.calibrated) out.push_back(v.projector);
  return out;
}

OverlayCounts OverlayInputs::counts() const {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  OverlayCounts c;
  for (const auto& [id, h] : heads_) c.heads += now - h.seen <= head_timeout_ ? 1 : 0;
  for (const auto& [id, v] : projectors_) {
    c.projectors += v.calibrated ? 1 : 0;
    c.thumbnails += v.thumbnail.empty() ? 0 : 1;
  }
  return c;
}

}  // namespace studio::preview

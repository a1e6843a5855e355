#include "capture/freed.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

namespace studio::capture {
namespace {

bool finite(double v) { return std::isfinite(v); }

// Linear interpolation of every lens parameter.
LensSample mix(const LensSample& a, const LensSample& b, double t) {
  auto lerp = [t](double x, double y) { return x + (y - x) * t; };
  LensSample s = a;
  s.fx = lerp(a.fx, b.fx);
  s.fy = lerp(a.fy, b.fy);
  s.cx = lerp(a.cx, b.cx);
  s.cy = lerp(a.cy, b.cy);
  s.rd3 = lerp(a.rd3, b.rd3);
  s.rd5 = lerp(a.rd5, b.rd5);
  return s;
}

// Samples of one zoom level sorted by focus → the parameters at `focus` (clamped).
LensSample along_focus(const std::vector<const LensSample*>& level, uint32_t focus) {
  if (focus <= level.front()->focus) return *level.front();
  if (focus >= level.back()->focus) return *level.back();
  auto hi = std::upper_bound(level.begin(), level.end(), focus,
                             [](uint32_t f, const LensSample* s) { return f < s->focus; });
  const LensSample* b = *hi;
  const LensSample* a = *(hi - 1);
  return mix(*a, *b, double(focus - a->focus) / double(b->focus - a->focus));
}

}  // namespace

Expected<FreeDPacket> decode_freed(std::span<const uint8_t> bytes, FreeDReject* reason) {
  FreeDPacket packet;
  const auto rejected = detail::parse_freed(bytes, &packet);
  if (!rejected) return packet;
  if (reason) *reason = *rejected;
  switch (*rejected) {
    case FreeDReject::wrong_length:
      return fail("free-d: expected a 29-byte D1 message, got " + std::to_string(bytes.size()) +
                  " bytes");
    case FreeDReject::unknown_type: {
      char type[8];
      std::snprintf(type, sizeof type, "0x%02X", unsigned(bytes[0]));
      return fail(std::string("free-d: message type ") + type + " is not D1");
    }
    case FreeDReject::bad_checksum:
      break;
  }
  return fail("free-d: checksum " + std::to_string(bytes[kFreeDD1Size - 1]) + " != computed " +
              std::to_string(freed_checksum(bytes.first(kFreeDD1Size - 1))));
}

Expected<void> LensTable::validate() const {
  if (samples.empty()) return fail("lens table: no samples");
  std::map<std::pair<uint32_t, uint32_t>, std::size_t> seen;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const LensSample& s = samples[i];
    const std::string where = "lens table sample " + std::to_string(i);
    if (!finite(s.fx) || !finite(s.fy) || !finite(s.cx) || !finite(s.cy) || !finite(s.rd3) ||
        !finite(s.rd5)) {
      return fail(where + ": non-finite value");
    }
    if (s.fx <= 0 || s.fy <= 0) return fail(where + ": fx and fy must be positive");
    if (s.zoom > 0xFFFFFFu || s.focus > 0xFFFFFFu) {
      return fail(where + ": zoom/focus counts exceed 24 bits");
    }
    auto [it, inserted] = seen.emplace(std::make_pair(s.zoom, s.focus), i);
    if (!inserted) {
      return fail(where + ": same zoom " + std::to_string(s.zoom) + " and focus " +
                  std::to_string(s.focus) + " as sample " + std::to_string(it->second));
    }
  }
  return {};
}

LensSample LensTable::at(uint32_t zoom, uint32_t focus) const {
  // Group by zoom level, each level sorted by focus. Tables are small (tens of samples), so this
  // is rebuilt per call rather than cached (keeps LensTable a plain value).
  std::map<uint32_t, std::vector<const LensSample*>> levels;
  for (const LensSample& s : samples) levels[s.zoom].push_back(&s);
  for (auto& [z, level] : levels) {
    std::sort(level.begin(), level.end(),
              [](const LensSample* a, const LensSample* b) { return a->focus < b->focus; });
  }
  LensSample out;
  if (zoom <= levels.begin()->first) {
    out = along_focus(levels.begin()->second, focus);
  } else if (zoom >= levels.rbegin()->first) {
    out = along_focus(levels.rbegin()->second, focus);
  } else {
    auto hi = levels.upper_bound(zoom);
    auto lo = std::prev(hi);
    const LensSample a = along_focus(lo->second, focus);
    const LensSample b = along_focus(hi->second, focus);
    out = mix(a, b, double(zoom - lo->first) / double(hi->first - lo->first));
  }
  out.zoom = zoom;
  out.focus = focus;
  return out;
}

Expected<void> FreeDCameraOptions::validate() const {
  if (camera_id.empty()) return fail("free-d camera: camera_id is empty");
  if (width <= 0 || height <= 0) {
    return fail("free-d camera " + camera_id + ": width and height must be positive");
  }
  if (auto ok = lens.validate(); !ok) {
    return fail("free-d camera " + camera_id + ": " + ok.error().message);
  }
  for (const Rigid3* r : {&world_from_tracker, &head_from_lens}) {
    if (!r->translation.allFinite() || !r->rotation.coeffs().allFinite()) {
      return fail("free-d camera " + camera_id + ": non-finite mounting transform");
    }
  }
  return {};
}

Camera freed_to_camera(const FreeDPacket& packet, const FreeDCameraOptions& options) {
  const Rigid3 tracker_from_head(
      freed_world_from_head(packet.pan_deg, packet.tilt_deg, packet.roll_deg),
      freed_position_in_studio(packet.x_mm, packet.y_mm, packet.z_mm));
  const Rigid3 lens_from_cam(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix().eval(),
                             Eigen::Vector3d::Zero());
  const Rigid3 world_from_cam =
      options.world_from_tracker * tracker_from_head * options.head_from_lens * lens_from_cam;

  const LensSample lens = options.lens.at(packet.zoom, packet.focus);
  Camera camera;
  camera.id = options.camera_id;
  camera.width = options.width;
  camera.height = options.height;
  camera.intrinsics.fx = lens.fx;
  camera.intrinsics.fy = lens.fy;
  camera.intrinsics.cx = lens.cx;
  camera.intrinsics.cy = lens.cy;
  camera.distortion = (lens.rd3 == 0 && lens.rd5 == 0) ? Distortion::none()
                                                       : Distortion::radial(lens.rd3, lens.rd5);
  camera.cam_from_world = world_from_cam.inverse();
  return camera;
}

}  // namespace studio::capture

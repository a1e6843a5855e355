#include "capture/freed.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

namespace studio::capture {
namespace {

int32_t read_i24(const uint8_t* p) {
  uint32_t u = (uint32_t(p[0]) << 16) | (uint32_t(p[1]) << 8) | uint32_t(p[2]);
  if (u & 0x800000u) u |= 0xFF000000u;  // sign-extend bit 23
  return int32_t(u);
}
uint32_t read_u24(const uint8_t* p) {
  return (uint32_t(p[0]) << 16) | (uint32_t(p[1]) << 8) | uint32_t(p[2]);
}
void write_24(uint8_t* p, uint32_t v) {
  p[0] = uint8_t(v >> 16);
  p[1] = uint8_t(v >> 8);
  p[2] = uint8_t(v);
}
// Rounds value*scale to the nearest int24, saturating; NaN becomes 0.
uint32_t quantise_i24(double value, double scale) {
  double q = std::round(value * scale);
  if (!(q == q)) q = 0;
  q = std::clamp(q, -8388608.0, 8388607.0);
  return uint32_t(int32_t(q)) & 0xFFFFFFu;
}

constexpr double kAngleScale = 32768.0;  // counts per degree
constexpr double kMmScale = 64.0;        // counts per millimetre
constexpr double kDeg = M_PI / 180.0;

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

const char* to_string(FreeDReject reason) {
  switch (reason) {
    case FreeDReject::wrong_length: return "wrong_length";
    case FreeDReject::unknown_type: return "unknown_type";
    case FreeDReject::bad_checksum: return "bad_checksum";
  }
  return "unknown";
}

uint8_t freed_checksum(std::span<const uint8_t> first_28_bytes) {
  uint32_t sum = 0;
  for (std::size_t i = 0; i < first_28_bytes.size() && i < kFreeDD1Size - 1; ++i) {
    sum += first_28_bytes[i];
  }
  return uint8_t((0x40u - sum) & 0xFFu);
}

Expected<FreeDPacket> decode_freed(std::span<const uint8_t> bytes, FreeDReject* reason) {
  auto reject = [reason](FreeDReject r, std::string message) {
    if (reason) *reason = r;
    return fail("free-d: " + std::move(message));
  };
  if (bytes.size() != kFreeDD1Size) {
    return reject(FreeDReject::wrong_length, "expected a 29-byte D1 message, got " +
                                                 std::to_string(bytes.size()) + " bytes");
  }
  if (bytes[0] != kFreeDD1Type) {
    char type[8];
    std::snprintf(type, sizeof type, "0x%02X", unsigned(bytes[0]));
    return reject(FreeDReject::unknown_type, std::string("message type ") + type + " is not D1");
  }
  const uint8_t expected = freed_checksum(bytes.first(kFreeDD1Size - 1));
  if (bytes[kFreeDD1Size - 1] != expected) {
    return reject(FreeDReject::bad_checksum, "checksum " + std::to_string(bytes[28]) +
                                                 " != computed " + std::to_string(expected));
  }
  const uint8_t* p = bytes.data();
  FreeDPacket packet;
  packet.camera_id = p[1];
  packet.pan_deg = read_i24(p + 2) / kAngleScale;
  packet.tilt_deg = read_i24(p + 5) / kAngleScale;
  packet.roll_deg = read_i24(p + 8) / kAngleScale;
  packet.x_mm = read_i24(p + 11) / kMmScale;
  packet.y_mm = read_i24(p + 14) / kMmScale;
  packet.z_mm = read_i24(p + 17) / kMmScale;
  packet.zoom = read_u24(p + 20);
  packet.focus = read_u24(p + 23);
  packet.spare = uint16_t((uint16_t(p[26]) << 8) | p[27]);
  return packet;
}

std::array<uint8_t, kFreeDD1Size> encode_freed(const FreeDPacket& packet) {
  std::array<uint8_t, kFreeDD1Size> b{};
  b[0] = kFreeDD1Type;
  b[1] = packet.camera_id;
  write_24(&b[2], quantise_i24(packet.pan_deg, kAngleScale));
  write_24(&b[5], quantise_i24(packet.tilt_deg, kAngleScale));
  write_24(&b[8], quantise_i24(packet.roll_deg, kAngleScale));
  write_24(&b[11], quantise_i24(packet.x_mm, kMmScale));
  write_24(&b[14], quantise_i24(packet.y_mm, kMmScale));
  write_24(&b[17], quantise_i24(packet.z_mm, kMmScale));
  write_24(&b[20], std::min<uint32_t>(packet.zoom, 0xFFFFFFu));
  write_24(&b[23], std::min<uint32_t>(packet.focus, 0xFFFFFFu));
  b[26] = uint8_t(packet.spare >> 8);
  b[27] = uint8_t(packet.spare);
  b[28] = freed_checksum(std::span<const uint8_t>(b.data(), kFreeDD1Size - 1));
  return b;
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

Eigen::Matrix3d freed_world_from_head(double pan_deg, double tilt_deg, double roll_deg) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return (AngleAxisd(-pan_deg * kDeg, Vector3d::UnitY()) *
          AngleAxisd(tilt_deg * kDeg, Vector3d::UnitX()) *
          AngleAxisd(-roll_deg * kDeg, Vector3d::UnitZ()))
      .toRotationMatrix();
}

Eigen::Vector3d freed_position_in_studio(double x_mm, double y_mm, double z_mm) {
  return Eigen::Vector3d(x_mm, z_mm, -y_mm) / 1000.0;
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

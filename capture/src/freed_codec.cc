// The Free-D wire format and the fixed axis mapping: byte-level code without studio::Expected,
// so that the libFuzzer build (clang 14, which cannot instantiate std::expected) compiles it
// alone (capture/freed_fuzz.cc).
#include <algorithm>
#include <cmath>

#include "capture/freed.h"

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

}  // namespace

const char* to_string(FreeDReject reason) {
  switch (reason) {
    case FreeDReject::wrong_length:
      return "wrong_length";
    case FreeDReject::unknown_type:
      return "unknown_type";
    case FreeDReject::bad_checksum:
      return "bad_checksum";
    case FreeDReject::unknown_id:
      return "unknown_id";
    case FreeDReject::too_late:
      return "too_late";
    case FreeDReject::duplicate:
      return "duplicate";
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

std::optional<FreeDReject> detail::parse_freed(std::span<const uint8_t> bytes,
                                               FreeDPacket* packet) {
  if (bytes.size() != kFreeDD1Size) return FreeDReject::wrong_length;
  if (bytes[0] != kFreeDD1Type) return FreeDReject::unknown_type;
  if (bytes[kFreeDD1Size - 1] != freed_checksum(bytes.first(kFreeDD1Size - 1))) {
    return FreeDReject::bad_checksum;
  }
  const uint8_t* p = bytes.data();
  packet->camera_id = p[1];
  packet->pan_deg = read_i24(p + 2) / kAngleScale;
  packet->tilt_deg = read_i24(p + 5) / kAngleScale;
  packet->roll_deg = read_i24(p + 8) / kAngleScale;
  packet->x_mm = read_i24(p + 11) / kMmScale;
  packet->y_mm = read_i24(p + 14) / kMmScale;
  packet->z_mm = read_i24(p + 17) / kMmScale;
  packet->zoom = read_u24(p + 20);
  packet->focus = read_u24(p + 23);
  packet->spare = uint16_t((uint16_t(p[26]) << 8) | p[27]);
  return std::nullopt;
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

}  // namespace studio::capture

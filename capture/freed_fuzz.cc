// libFuzzer target for the Free-D D1 decoder (outside data from the network): any datagram is
// either rejected with a valid reason or decodes to a packet that re-encodes to the same bytes
// and maps to a finite proper rotation and position. Built from capture/src/freed_codec.cc alone
// (clang 14 cannot instantiate std::expected). `./studio fuzz freed_fuzz 300`
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>

#include "capture/freed.h"

using namespace studio::capture;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FreeDPacket packet;
  const auto rejected = detail::parse_freed(std::span<const uint8_t>(data, size), &packet);
  if (rejected) {
    if (size_t(*rejected) >= kFreeDRejectCount) std::abort();
    if (size == kFreeDD1Size && *rejected == FreeDReject::wrong_length) std::abort();
    return 0;
  }
  if (size != kFreeDD1Size) std::abort();
  const auto bytes = encode_freed(packet);
  if (std::memcmp(bytes.data(), data, kFreeDD1Size) != 0) std::abort();
  const Eigen::Matrix3d R = freed_world_from_head(packet.pan_deg, packet.tilt_deg, packet.roll_deg);
  const Eigen::Vector3d t = freed_position_in_studio(packet.x_mm, packet.y_mm, packet.z_mm);
  if (!R.allFinite() || !t.allFinite() || std::abs(R.determinant() - 1) > 1e-9 ||
      t.norm() > 1000) {  // |x|, |y|, |z| < 131.072 m
    std::abort();
  }
  return 0;
}

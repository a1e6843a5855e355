// libFuzzer target for the Free-D D1 decoder (outside data from the network): any datagram is
// either rejected with a reason or decodes to a packet that re-encodes to the same bytes and maps
// to a finite camera. `./studio fuzz freed_fuzz 300`
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>

#include "capture/freed.h"

using namespace studio::capture;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FreeDReject reason{};
  auto packet = decode_freed(std::span<const uint8_t>(data, size), &reason);
  if (!packet) {
    if (size_t(reason) >= kFreeDRejectCount || packet.error().message.empty()) std::abort();
    return 0;
  }
  if (size != kFreeDD1Size) std::abort();
  const auto bytes = encode_freed(*packet);
  if (std::memcmp(bytes.data(), data, kFreeDD1Size) != 0) std::abort();

  static const FreeDCameraOptions options = [] {
    FreeDCameraOptions o;
    o.camera_id = "fuzz";
    o.width = 704;
    o.height = 576;
    o.lens.samples = {{0, 0, 600, 600, 352, 288, -0.1, 0.01},
                      {0, 60000, 650, 650, 352, 288, -0.1, 0.01},
                      {1u << 23, 0, 3000, 3000, 350, 290, 0, 0}};
    return o;
  }();
  const studio::Camera camera = freed_to_camera(*packet, options);
  if (!camera.cam_from_world.translation.allFinite() || !std::isfinite(camera.intrinsics.fx) ||
      std::abs(camera.cam_from_world.R().determinant() - 1) > 1e-9) {
    std::abort();
  }
  return 0;
}

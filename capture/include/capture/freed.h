#pragma once
// Free-D camera tracking (BBC R&D / Vinten "free-d", message type D1), decoded into the studio's
// camera model so a moving, zooming camera carries a calibration per frame (DESIGN §3:
// `studio/camera/calibration` "from rig file or Free-D").
//
// The D1 message: 29 bytes, big-endian.
//   [0]      0xD1 message type        [1]      camera id
//   [2..4]   pan   int24, 1/32768 deg [5..7]   tilt  int24, 1/32768 deg
//   [8..10]  roll  int24, 1/32768 deg
//   [11..13] X     int24, 1/64 mm     [14..16] Y     int24, 1/64 mm
//   [17..19] Z     int24, 1/64 mm (height, positive up)
//   [20..22] zoom  uint24, lens encoder counts
//   [23..25] focus uint24, lens encoder counts
//   [26..27] spare / user defined     [28]     checksum = (0x40 - sum of bytes 0..27) mod 256
//
// Free-D conventions (Vinten free-d installation manual, appendix B):
// - X and Y horizontal, Z = height (positive up); a right-handed tracker frame.
// - pan:  angle about the vertical between the tracker's +Y axis and the horizontal projection
//         of the optical axis; positive = clockwise seen from above (panning right).
// - tilt: elevation of the optical axis; positive = tilting up.
// - roll: about the optical axis; positive = clockwise seen from behind the camera.
//
// Axis mapping to the studio frame (metres, y up, floor = xz-plane), chosen and fixed here:
//   studio x =  X / 1000,   studio y = Z / 1000,   studio z = -Y / 1000
// (a proper rotation: the tracker's forward +Y becomes the studio's -z, its height the studio's
// y). With pan = tilt = roll = 0 the camera looks along studio -z with its image "up" along
// studio +y and image "right" along studio +x. The head orientation is
//   world_from_head = Ry(-pan) * Rx(tilt) * Rz(-roll)
// (pan outermost, as on a pan/tilt head; Ry(-pan) because a positive pan turns from -z towards
// +x), and the OpenCV camera axes (x right, y down, z forward) are diag(1, -1, -1) in the head
// frame. Two configurable rigid offsets complete the chain:
//   world_from_cam = world_from_tracker * T(position) * world_from_head * head_from_lens * R_cv
// world_from_tracker places the tracker's origin/heading in the studio (identity when the
// tracking system was surveyed in studio axes) and head_from_lens is the mounting offset of the
// lens' entrance pupil relative to the tracked point (in head axes: x right, y up, z backward).
//
// Lens: zoom and focus counts map to intrinsics through a per-lens table (LensTable below), the
// paper's radial model r = r' + rd3 r'^3 + rd5 r'^5 included.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "core/transform.h"

namespace studio::capture {

inline constexpr std::size_t kFreeDD1Size = 29;
inline constexpr uint8_t kFreeDD1Type = 0xD1;
inline constexpr uint16_t kFreeDDefaultPort = 40000;

// Why a datagram was rejected; used as an index into per-reason counters. The first three are
// the decoder's (malformed); the others the listener's (freed_listener.h): a camera id no camera
// of this process takes, a packet for a frame already delivered, a second packet for one frame.
enum class FreeDReject : uint8_t {
  wrong_length = 0,
  unknown_type = 1,
  bad_checksum = 2,
  unknown_id = 3,
  too_late = 4,
  duplicate = 5,
};
inline constexpr std::size_t kFreeDRejectCount = 6;
const char* to_string(FreeDReject reason);

struct FreeDPacket {
  uint8_t camera_id = 0;
  double pan_deg = 0, tilt_deg = 0, roll_deg = 0;  // 1/32768 degree resolution
  double x_mm = 0, y_mm = 0, z_mm = 0;             // 1/64 mm resolution; z = height
  uint32_t zoom = 0, focus = 0;                    // 24-bit encoder counts
  uint16_t spare = 0;
};

// Decodes one datagram. Never reads outside `bytes`, never throws; on rejection returns an Error
// with one line and, when `reason` is given, stores why.
Expected<FreeDPacket> decode_freed(std::span<const uint8_t> bytes, FreeDReject* reason = nullptr);

namespace detail {
// The decoder behind decode_freed(), without Expected (the fuzz build's clang 14 cannot
// instantiate std::expected): nullopt with *packet filled, or the reason.
std::optional<FreeDReject> parse_freed(std::span<const uint8_t> bytes, FreeDPacket* packet);
}  // namespace detail

// Encodes a packet (rounding to the wire resolution, saturating out-of-range values) with a
// valid checksum. decode_freed(encode_freed(p)) == p up to the wire resolution.
std::array<uint8_t, kFreeDD1Size> encode_freed(const FreeDPacket& packet);

// checksum byte for bytes[0..27]: (0x40 - sum) mod 256.
uint8_t freed_checksum(std::span<const uint8_t> first_28_bytes);

// One calibrated lens state. Intrinsics in pixels for the camera's full image size.
struct LensSample {
  uint32_t zoom = 0;
  uint32_t focus = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double rd3 = 0, rd5 = 0;  // the paper's radial model (normalised coordinates)
};

// Zoom/focus counts → intrinsics. The samples need not form a full grid: they are grouped by
// zoom count; within a zoom level the parameters are linear in focus (clamped to the level's
// focus range), and between the two zoom levels that bracket the query they are linear in zoom
// (clamped to the table's zoom range). A single sample is a fixed lens.
struct LensTable {
  std::vector<LensSample> samples;

  // At least one sample; finite values; fx, fy > 0; no two samples at the same (zoom, focus).
  Expected<void> validate() const;
  // Requires validate() to have succeeded.
  LensSample at(uint32_t zoom, uint32_t focus) const;
};

// Everything needed to turn a D1 packet into a studio::Camera (the camera's section of the
// capture config; YAML parsing lives in the capture node).
struct FreeDCameraOptions {
  std::string camera_id;      // studio camera id (the Camera::id of the result)
  uint8_t freed_id = 0;       // the D1 camera id byte of this camera's tracker
  int width = 0, height = 0;  // image size the lens table's pixels refer to
  LensTable lens;
  Rigid3 world_from_tracker;  // tracker frame (after the fixed axis mapping) → studio frame
  Rigid3 head_from_lens;      // mounting offset of the entrance pupil (metres, head axes)

  Expected<void> validate() const;
};

// The head orientation of the mapping above, in studio axes (x right, y up, z backward at rest).
Eigen::Matrix3d freed_world_from_head(double pan_deg, double tilt_deg, double roll_deg);
// Tracker position (mm, Free-D axes) → studio axes in metres, before world_from_tracker.
Eigen::Vector3d freed_position_in_studio(double x_mm, double y_mm, double z_mm);

// The per-frame calibration of a tracked camera. `options` must have passed validate().
Camera freed_to_camera(const FreeDPacket& packet, const FreeDCameraOptions& options);

}  // namespace studio::capture

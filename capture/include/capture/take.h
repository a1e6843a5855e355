#pragma once
// The on-disk take format (DESIGN §4): takes/<take>/<camera_id>/ holds
//
//   frames.raw  append-only frames, each a 48-byte header followed by its payload:
//                 off  size  field
//                   0     4  magic "STFR"
//                   4     2  version (1)
//                   6     2  pixel format (1 = RGB8, 2 = MONO8)
//                   8     8  frame number (DESIGN §5)
//                  16     8  capture_ns (CLOCK_REALTIME)
//                  24     4  width
//                  28     4  height
//                  32     8  payload size in bytes (= width * height * bytes per pixel)
//                  40     4  CRC-32 of header bytes 0..39 followed by the payload
//                  44     4  reserved, 0
//               all little-endian. A frame is intact iff its header is well formed, its payload
//               is complete and the CRC matches.
//   index       "STIX" + version u32, then per frame: frame number u64, byte offset u64 of its
//               header in frames.raw. Derived data: rebuild_index() recreates it from frames.raw
//               (after a crash the index may be short or missing).
//   take.yaml   camera, format, size, requested start/stop, first/last recorded frame, frame
//               count, drops, status (recording | complete | error) and the camera calibration.
//               Written at take start, rewritten (atomically, via rename) at the end; on a
//               full disk rewritten in place (it is padded to 4 KiB for that).
//
// scan_frames() walks frames.raw from the start: it stops at the first header that is not well
// formed (garbage, or a torn write: a partial header or payload at the end, as a kill -9 or a
// power cut mid-write leaves) and reports where; a complete frame whose CRC does not match is
// counted as corrupt and skipped (its header sizes were sane, so the next frame is found).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::capture {

inline constexpr char kFramesFile[] = "frames.raw";
inline constexpr char kIndexFile[] = "index";
inline constexpr char kTakeFile[] = "take.yaml";
inline constexpr std::size_t kFrameHeaderSize = 48;
inline constexpr uint16_t kTakeVersion = 1;
// Frames larger than this are rejected as malformed headers (16k x 16k RGB would be 768 MiB).
inline constexpr uint64_t kMaxFramePayload = 1ull << 30;

enum class PixelFormat : uint16_t { kRgb8 = 1, kMono8 = 2 };
const char* pixel_format_name(PixelFormat format);
int bytes_per_pixel(PixelFormat format);

struct FrameHeader {
  uint64_t frame = 0;
  int64_t capture_ns = 0;
  uint32_t width = 0;
  uint32_t height = 0;
  PixelFormat format = PixelFormat::kRgb8;
  uint64_t payload_size = 0;
  uint32_t crc = 0;
};

// Serialises `header` with the CRC of (header bytes 0..39, payload) into `out`; returns the CRC.
uint32_t encode_frame_header(const FrameHeader& header, std::span<const uint8_t> payload,
                             uint8_t (&out)[kFrameHeaderSize]);
// Parses and checks a header (magic, version, format, size consistency); the CRC is checked by
// frame_crc_matches() once the payload is read. Error: one line naming what is wrong.
Expected<FrameHeader> decode_frame_header(std::span<const uint8_t> bytes);
bool frame_crc_matches(std::span<const uint8_t> header_bytes, std::span<const uint8_t> payload);

struct IndexEntry {
  uint64_t frame = 0;
  uint64_t offset = 0;
  friend bool operator==(const IndexEntry&, const IndexEntry&) = default;
};

struct ScanReport {
  std::vector<IndexEntry> intact;  // intact frames in file order
  uint64_t corrupt = 0;            // complete frames whose CRC does not match (skipped)
  uint64_t file_bytes = 0;
  uint64_t valid_bytes = 0;  // offset just past the last well-formed frame
  std::string tail;          // why the scan stopped before file_bytes ("" = clean end)
  std::optional<uint64_t> first_frame, last_frame;
  uint32_t width = 0, height = 0;  // of the first intact frame
  PixelFormat format = PixelFormat::kRgb8;
};

// Scans <dir>/frames.raw. Error only if the file cannot be opened or read.
Expected<ScanReport> scan_frames(const std::string& take_dir);

// fsync() of a folder: makes the renames and creations in it durable.
Expected<void> sync_directory(const std::string& dir);

// Writes <dir>/index from `entries` atomically (index.tmp + rename + folder sync).
Expected<void> write_index(const std::string& take_dir, std::span<const IndexEntry> entries);
// Reads <dir>/index; Error if missing or malformed (wrong magic, partial entry).
Expected<std::vector<IndexEntry>> read_index(const std::string& take_dir);

// Reads frame `entry` (header + payload) from frames.raw and checks it; payload into `pixels`.
Expected<FrameHeader> read_frame(const std::string& take_dir, const IndexEntry& entry,
                                 std::vector<uint8_t>& pixels);

// Metadata of one camera's take (take.yaml). The calibration is an already formatted YAML
// mapping body (the node formats it; this library has no YAML dependency), written indented under
// `calibration:`, verbatim: every line must already be indented (by 2 spaces, e.g.
// yaml::format_camera(camera, 2)); empty = none.
struct TakeInfo {
  std::string take;
  std::string camera_id;
  PixelFormat format = PixelFormat::kRgb8;
  uint32_t width = 0, height = 0;
  int64_t period_ns = 0;                            // studio frame period
  uint64_t start_frame = 0;                         // requested first frame
  std::optional<uint64_t> stop_frame;               // requested end (exclusive), if known
  std::optional<uint64_t> first_frame, last_frame;  // recorded
  uint64_t frames = 0;                              // recorded frames
  uint64_t drops = 0;                // frames not recorded (source drops + queue overflow)
  std::string status = "recording";  // recording | complete | error
  std::string error;                 // when status == error
  std::string calibration_yaml;      // mapping body lines, each indented by 2 spaces
};

std::string format_take_yaml(const TakeInfo& info);
// Atomic write (take.yaml.tmp + fsync + rename + folder sync). The text is padded with a trailing comment to
// kTakeYamlReserve bytes; when the atomic write fails (a full disk), the existing take.yaml is
// overwritten in place instead if the new text fits in it (no new blocks needed).
inline constexpr std::size_t kTakeYamlReserve = 4096;
Expected<void> write_take_yaml(const std::string& take_dir, const TakeInfo& info);

}  // namespace studio::capture

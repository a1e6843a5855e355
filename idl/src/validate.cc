// Validators for every topic type (wire/types.h): the trust boundary between the network and
// the pure libraries. They check ids, enum ranges, sizes against header fields, finiteness,
// and the ordering invariants of mask runs (core/run_mask.h) and hull intervals. AlphaMask
// payloads in MASK_CODEC form are decoded with the mask codec (core/mask_codec.h), which rejects
// anything that is not exactly a valid mask.

#include <cmath>
#include <cstring>

#include "core/mask_codec.h"
#include "wire/sample.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

constexpr uint32_t kMaxSide = 16384;     // image / mask sides
constexpr uint32_t kMaxGridSide = 4096;  // hull grid sides
constexpr uint64_t kMaxGridColumns = 1u << 22;

template <std::size_t N>
bool id_ok(const char (&id)[N]) {
  return id[0] != '\0' && std::memchr(id, 0, N) != nullptr;
}
template <std::size_t N>
bool text_ok(const char (&s)[N]) {  // may be empty, must be terminated
  return std::memchr(s, 0, N) != nullptr;
}
bool finite(std::span<const double> v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
bool finite(std::span<const float> v) {
  for (float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
// Enum fields come off the wire as raw 32-bit values: read them as integers (loading an
// out-of-range value as the C enum type is undefined behaviour).
template <class E>
uint32_t raw(const E& e) {
  static_assert(sizeof(E) == sizeof(uint32_t));
  uint32_t v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}
bool side_ok(uint32_t w, uint32_t h, uint32_t max = kMaxSide) {
  return w >= 1 && h >= 1 && w <= max && h <= max;
}
// Pinhole K: finite, fx, fy > 0, last row 0 0 1.
Verdict check_K(const double (&K)[9]) {
  if (!finite(K)) return Reject::non_finite;
  if (!(K[0] > 0 && K[4] > 0) || K[6] != 0 || K[7] != 0 || K[8] != 1) return Reject::out_of_range;
  return std::nullopt;
}
// R: finite and orthonormal with det +1 (to 1e-6 per entry of R Rᵀ − I).
Verdict check_R(const double (&R)[9]) {
  if (!finite(R)) return Reject::non_finite;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k) d += R[3 * i + k] * R[3 * j + k];
      if (std::abs(d - (i == j ? 1.0 : 0.0)) > 1e-6) return Reject::out_of_range;
    }
  const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                     R[2] * (R[3] * R[7] - R[4] * R[6]);
  if (det < 0) return Reject::out_of_range;
  return std::nullopt;
}

// Runs of a w x h mask in MASK_RUNS form (AlphaMask, ProjectorFrame's blackout mask).
Verdict check_runs(std::span<const uint32_t> row_start, std::span<const uint32_t> runs,
                   uint32_t width, uint32_t height) {
  if (row_start.size() != uint64_t(height) + 1 || runs.size() % 2 != 0) return Reject::bad_size;
  if (row_start.front() != 0 || uint64_t(row_start.back()) * 2 != runs.size())
    return Reject::bad_size;
  uint64_t area = 0;
  for (uint32_t y = 0; y < height; ++y) {
    const uint32_t a = row_start[y], b = row_start[y + 1];
    if (b < a) return Reject::bad_runs;
    int64_t prev_end = -1;
    for (uint32_t r = a; r < b; ++r) {
      const uint32_t begin = runs[2 * r], end = runs[2 * r + 1];
      // RunMask invariant: begin < end <= width, runs sorted and not touching.
      if (begin >= end || end > width || int64_t(begin) <= prev_end) return Reject::bad_runs;
      prev_end = end;
      area += end - begin;
    }
  }
  if (area > uint64_t(width) * height) return Reject::bad_runs;  // implied; kept explicit
  return std::nullopt;
}

Verdict check_mask_runs(const studio_AlphaMask& s) {
  if (!view(s.data).empty()) return Reject::bad_size;
  return check_runs(view(s.row_start), view(s.runs), s.width, s.height);
}

Verdict check_mask_codec(const studio_AlphaMask& s) {
  if (!view(s.row_start).empty() || !view(s.runs).empty()) return Reject::bad_size;
  // The decoder rejects anything that is not exactly a valid mask; the decoded mask is reused
  // per thread so validation does not allocate in the steady state.
  thread_local RunMask scratch(0, 0);
  auto mask = decode_mask(view(s.data), std::move(scratch));
  if (!mask) {
    scratch = RunMask(0, 0);
    return Reject::bad_runs;
  }
  const bool sizes_match =
      uint32_t(mask->width()) == s.width && uint32_t(mask->height()) == s.height;
  scratch = std::move(*mask);
  if (!sizes_match) return Reject::bad_size;
  return std::nullopt;
}

}  // namespace

Verdict validate(const studio_CameraCalibration& s) {
  if (!id_ok(s.camera_id)) return Reject::bad_id;
  if (!side_ok(s.width, s.height)) return Reject::bad_size;
  if (auto v = check_K(s.K)) return v;
  if (!std::isfinite(s.rd3) || !std::isfinite(s.rd5) || !finite(s.t)) return Reject::non_finite;
  return check_R(s.R);
}

Verdict validate(const studio_AlphaMask& s) {
  if (!id_ok(s.camera_id)) return Reject::bad_id;
  if (!side_ok(s.width, s.height)) return Reject::bad_size;
  switch (raw(s.encoding)) {
    case studio_MASK_RUNS:
      return check_mask_runs(s);
    case studio_MASK_CODEC:
      return check_mask_codec(s);
  }
  return Reject::out_of_range;
}

// The image payload of CameraImage and ImageReply: its length against the size and format.
static Verdict check_image(uint32_t width, uint32_t height, uint32_t format, std::span<const uint8_t> d) {
  if (!side_ok(width, height)) return Reject::bad_size;
  const uint64_t n = d.size(), pixels = uint64_t(width) * height;
  switch (format) {
    case studio_IMAGE_RGB8:
      return n == 3 * pixels ? Verdict{} : Reject::bad_size;
    case studio_IMAGE_MONO8:
      return n == pixels ? Verdict{} : Reject::bad_size;
    case studio_IMAGE_JPEG: {
      if (n < 4 || n > 3 * pixels + 65536) return Reject::bad_size;
      if (d[0] != 0xFF || d[1] != 0xD8) return Reject::out_of_range;  // SOI marker
      return std::nullopt;
    }
  }
  return Reject::out_of_range;
}

Verdict validate(const studio_CameraImage& s) {
  if (!id_ok(s.camera_id)) return Reject::bad_id;
  return check_image(s.width, s.height, raw(s.format), view(s.data));
}

Verdict validate(const studio_CameraState& s) {
  if (!id_ok(s.camera_id)) return Reject::bad_id;
  if (!text_ok(s.take) || !text_ok(s.error)) return Reject::bad_id;
  for (const auto& f : view(s.features)) {
    if (!id_ok(f.name)) return Reject::bad_id;
    if (!std::isfinite(f.value) || !std::isfinite(f.min) || !std::isfinite(f.max))
      return Reject::non_finite;
    if (f.min > f.max) return Reject::out_of_range;
  }
  if (!std::isfinite(s.fps)) return Reject::non_finite;
  if (s.fps < 0 || raw(s.state) > studio_CAMERA_ERROR ||
      raw(s.time_source) > studio_TIME_STUDIO_CLOCK)
    return Reject::out_of_range;
  return std::nullopt;
}

Verdict validate(const studio_CameraControl& s) {
  if (!id_ok(s.camera_id) || !id_ok(s.feature)) return Reject::bad_id;
  if (!std::isfinite(s.value)) return Reject::non_finite;
  return std::nullopt;
}

Verdict validate(const studio_CaptureCommand& s) {
  if (!id_ok(s.take)) return Reject::bad_id;
  if (raw(s.action) > studio_CAPTURE_STOP) return Reject::out_of_range;
  return std::nullopt;
}

Verdict validate(const studio_SegmentSet& s) {
  if (!id_ok(s.actor_id)) return Reject::bad_id;
  if (!side_ok(s.nu, s.nv, kMaxGridSide) || uint64_t(s.nu) * s.nv > kMaxGridColumns)
    return Reject::bad_size;
  if (!finite(s.box_min) || !finite(s.box_max)) return Reject::non_finite;
  for (int i = 0; i < 3; ++i)
    if (!(s.box_min[i] < s.box_max[i])) return Reject::out_of_range;
  if (s.axis > 2) return Reject::out_of_range;
  auto start = view(s.interval_start);
  auto iv = view(s.intervals);
  const uint64_t columns = uint64_t(s.nu) * s.nv;
  if (start.size() != columns + 1 || iv.size() % 2 != 0) return Reject::bad_size;
  if (start.front() != 0 || uint64_t(start.back()) * 2 != iv.size()) return Reject::bad_size;
  if (!finite(iv)) return Reject::non_finite;
  const float lo = s.box_min[s.axis], hi = s.box_max[s.axis];
  for (uint64_t c = 0; c < columns; ++c) {
    if (start[c + 1] < start[c]) return Reject::bad_runs;
    float prev_end = lo;
    for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
      const float b = iv[2 * k], e = iv[2 * k + 1];
      if (b > e || b < prev_end || e > hi) return Reject::bad_runs;
      prev_end = e;
    }
  }
  return std::nullopt;
}

Verdict validate(const studio_ActorMesh& s) {
  if (!id_ok(s.actor_id)) return Reject::bad_id;
  auto v = view(s.vertices), n = view(s.normals);
  auto t = view(s.triangles);
  if (v.size() % 3 != 0 || t.size() % 3 != 0) return Reject::bad_size;
  if (!n.empty() && n.size() != v.size()) return Reject::bad_size;
  if (!finite(v) || !finite(n)) return Reject::non_finite;
  const uint64_t nv = v.size() / 3;
  for (uint32_t i : t)
    if (i >= nv) return Reject::out_of_range;
  return std::nullopt;
}

Verdict validate(const studio_HeadPose& s) {
  if (!id_ok(s.actor_id)) return Reject::bad_id;
  if (!finite(s.position) || !finite(s.velocity) || !std::isfinite(s.confidence))
    return Reject::non_finite;
  if (s.confidence < 0 || s.confidence > 1) return Reject::out_of_range;
  return std::nullopt;
}

// SceneNode, SceneCommand and SceneState: idl/src/scene_validate.cc.

Verdict validate(const studio_ProjectorCalibration& s) {
  if (!id_ok(s.projector_id)) return Reject::bad_id;
  if (!side_ok(s.width, s.height)) return Reject::bad_size;
  if (auto v = check_K(s.K)) return v;
  if (!finite(s.t) || !finite(s.screen_corners) || !finite(s.homography)) return Reject::non_finite;
  return check_R(s.R);
}

Verdict validate(const studio_ServiceStatus& s) {
  if (!id_ok(s.service) || !id_ok(s.instance) || !text_ok(s.host)) return Reject::bad_id;
  if (raw(s.state) > studio_SERVICE_FAILED) return Reject::out_of_range;
  if (!std::isfinite(s.input_hz) || !std::isfinite(s.output_hz) || !std::isfinite(s.latency_ms))
    return Reject::non_finite;
  if (s.input_hz < 0 || s.output_hz < 0 || s.latency_ms < 0) return Reject::out_of_range;
  for (const auto& c : view(s.counters)) {
    if (!id_ok(c.name)) return Reject::bad_id;
    if (!std::isfinite(c.value)) return Reject::non_finite;
  }
  return std::nullopt;
}

Verdict validate(const studio_ProjectorMask& s) {
  if (!id_ok(s.projector_id)) return Reject::bad_id;
  if (!side_ok(s.width, s.height)) return Reject::bad_size;
  if (s.step < 1 || s.step > 64) return Reject::out_of_range;
  return check_runs(view(s.row_start), view(s.runs), s.width, s.height);
}

Verdict validate(const studio_ProjectorFrame& s) {
  if (!id_ok(s.projector_id)) return Reject::bad_id;
  if (!side_ok(s.width, s.height)) return Reject::bad_size;
  if (!finite(s.eye) || !std::isfinite(s.latency_ms) || !std::isfinite(s.margin_m))
    return Reject::non_finite;
  if (s.latency_ms < 0 || s.margin_m < 0) return Reject::out_of_range;
  if (s.thumb_width > kMaxSide || s.thumb_height > kMaxSide ||
      view(s.thumbnail).size() != uint64_t(s.thumb_width) * s.thumb_height * 3)
    return Reject::bad_size;
  return check_runs(view(s.mask_row_start), view(s.mask_runs), s.width, s.height);
}

Verdict validate(const studio_ImageRequest& s) {
  if (!id_ok(s.requester) || !id_ok(s.camera_id)) return Reject::bad_id;
  return std::nullopt;
}

// OK carries an image of exactly its size and format; the other statuses carry none.
Verdict validate(const studio_ImageReply& s) {
  if (!id_ok(s.requester) || !id_ok(s.camera_id)) return Reject::bad_id;
  switch (raw(s.status)) {
    case studio_IMAGE_REPLY_OK:
      return check_image(s.width, s.height, raw(s.format), view(s.data));
    case studio_IMAGE_REPLY_EVICTED:
    case studio_IMAGE_REPLY_NOT_YET:
      return view(s.data).empty() ? Verdict{} : Reject::bad_size;
  }
  return Reject::out_of_range;
}

}  // namespace studio::wire

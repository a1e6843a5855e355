#include "wire/capture_convert.h"

#include <algorithm>
#include <span>

#include "wire/convert.h"

namespace studio::wire {

void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns,
               const std::vector<uint8_t>& codec_bytes, int width, int height,
               wire::Owned<studio_AlphaMask>& out) {
  wire::set(out->camera_id, camera_id);
  out->frame = frame;
  out->capture_ns = capture_ns;
  out->width = uint32_t(width);
  out->height = uint32_t(height);
  out->encoding = studio_MASK_CODEC;
  wire::resize(out->row_start, 0);
  wire::resize(out->runs, 0);
  wire::assign(out->data, codec_bytes);
}

Expected<PaperModelFit> from_core(const Camera& camera, uint64_t frame, int64_t capture_ns,
                                  bool tracked, wire::Owned<studio_CameraCalibration>& out,
                                  const PaperModelOptions& options) {
  auto fit = to_paper_model(camera, options);
  if (!fit) return std::unexpected(fit.error());
  if (auto ok = from_core(fit->camera, *out); !ok) return std::unexpected(ok.error());
  out->frame = frame;
  out->capture_ns = capture_ns;
  out->tracked = tracked;
  return fit;
}

void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns, int width,
               int height, bool jpeg, const std::vector<uint8_t>& data,
               wire::Owned<studio_CameraImage>& out) {
  wire::set(out->camera_id, camera_id);
  out->frame = frame;
  out->capture_ns = capture_ns;
  out->width = uint32_t(width);
  out->height = uint32_t(height);
  out->format = jpeg ? studio_IMAGE_JPEG : studio_IMAGE_RGB8;
  wire::assign(out->data, data);
}

void from_core(const CameraStateCore& s, wire::Owned<studio_CameraState>& out) {
  wire::set(out->camera_id, s.camera_id);
  out->frame = s.frame;
  out->capture_ns = s.capture_ns;
  std::vector<studio_CameraFeature> features;
  for (const auto& f : s.features) {
    if (features.size() == 64) break;  // IDL bound
    studio_CameraFeature cf{};
    wire::set(cf.name, f.name.substr(0, sizeof cf.name - 1));
    cf.value = f.value;
    cf.min = f.min;
    cf.max = f.max;
    features.push_back(cf);
  }
  wire::assign(out->features, features);
  out->fps = s.fps;
  out->drops = s.drops;
  out->recording = s.recording;
  wire::set(out->take, s.take.substr(0, sizeof out->take - 1));
  switch (s.state) {
    case CameraStateCore::Run::kStopped:
      out->state = studio_CAMERA_STOPPED;
      break;
    case CameraStateCore::Run::kStreaming:
      out->state = studio_CAMERA_STREAMING;
      break;
    case CameraStateCore::Run::kRecording:
      out->state = studio_CAMERA_RECORDING;
      break;
    case CameraStateCore::Run::kError:
      out->state = studio_CAMERA_ERROR;
      break;
  }
  wire::set(out->error, s.error.substr(0, sizeof out->error - 1));
  out->calibration_valid = s.calibration_valid;
  switch (s.time_source) {
    case capture::TimeSource::host_arrival:
      out->time_source = studio_TIME_HOST_ARRIVAL;
      break;
    case capture::TimeSource::camera:
      out->time_source = studio_TIME_CAMERA;
      break;
    case capture::TimeSource::camera_ptp:
      out->time_source = studio_TIME_CAMERA_PTP;
      break;
    case capture::TimeSource::studio_clock:
      out->time_source = studio_TIME_STUDIO_CLOCK;
      break;
  }
}

CaptureCommandCore to_core(const studio_CaptureCommand& c) {
  return {std::string(wire::str(c.take)), c.action == studio_CAPTURE_START, c.at_frame};
}

CameraControlCore to_core(const studio_CameraControl& c) {
  return {std::string(wire::str(c.camera_id)), std::string(wire::str(c.feature)), c.value};
}

}  // namespace studio::wire

#pragma once
// IDL samples <-> core types of the camera topics the capture node writes and reads (DESIGN §2
// rule 1): studio/camera/{mask, calibration, image, state, control} and studio/capture/command.
// The one conversion per topic lives in idl/: the payload-level AlphaMask and CameraCalibration
// conversions are wire/convert.h's; these add the sample's header (camera_id, frame, capture_ns).
// Library `studio_wire_capture` (links studio_wire and, for the pure type capture::Feature,
// studio_capture_record). Writers fill Owned samples; readers get validated samples (wire/types.h
// validators ran).

#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "core/camera.h"
#include "core/distortion_fit.h"
#include "core/error.h"
#include "wire/sample.h"

namespace studio::wire {

// AlphaMask with the mask codec's bytes (MASK_CODEC).
void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns,
               const std::vector<uint8_t>& codec_bytes, int width, int height,
               wire::Owned<studio_AlphaMask>& out);

// CameraCalibration of `camera` at (frame, capture_ns): wire::from_core(camera) (wire/convert.h)
// plus the header. The wire carries the paper's radial model r = r' + rd3 r'^3 + rd5 r'^5, so a
// camera with OpenCV distortion is converted explicitly by to_paper_model (core/distortion_fit.h:
// least-squares fit over the image) and refused with that fit's one-line error when its residual
// exceeds options.max_residual_px. Returns the fit (residual 0, fitted = false for a camera
// already in the paper's model).
Expected<PaperModelFit> from_core(const Camera& camera, uint64_t frame, int64_t capture_ns,
                                  bool tracked, wire::Owned<studio_CameraCalibration>& out,
                                  const PaperModelOptions& options = {});

// CameraImage holding `data` (JPEG bytes or raw RGB8).
void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns, int width,
               int height, bool jpeg, const std::vector<uint8_t>& data,
               wire::Owned<studio_CameraImage>& out);

struct CameraStateCore {
  std::string camera_id;
  uint64_t frame = 0;
  int64_t capture_ns = 0;
  std::vector<capture::Feature> features;
  double fps = 0;
  uint64_t drops = 0;
  bool recording = false;
  std::string take;  // pending or recording take ("" = none)
  enum class Run { kStopped, kStreaming, kRecording, kError } state = Run::kStopped;
  std::string error;
  bool calibration_valid = true;
  capture::TimeSource time_source = capture::TimeSource::host_arrival;
};
void from_core(const CameraStateCore& s, wire::Owned<studio_CameraState>& out);

struct CaptureCommandCore {
  std::string take;
  bool start = true;
  uint64_t at_frame = 0;
};
CaptureCommandCore to_core(const studio_CaptureCommand& c);

struct CameraControlCore {
  std::string camera_id, feature;
  double value = 0;
};
CameraControlCore to_core(const studio_CameraControl& c);

}  // namespace studio::wire

#pragma once
// IDL samples <-> core types for the capture node (DESIGN §2 rule 1: the only place that knows
// both). Writers fill Owned samples; readers get validated samples (wire/types.h validators ran).

#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "core/camera.h"
#include "core/image.h"
#include "core/mask_codec.h"
#include "core/run_mask.h"
#include "wire/sample.h"

namespace studio::capture::node {

// AlphaMask with the mask codec's bytes (MASK_CODEC).
void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns,
               const std::vector<uint8_t>& codec_bytes, int width, int height,
               wire::Owned<studio_AlphaMask>& out);

// CameraCalibration from a studio::Camera (K, paper radial terms, cam_from_world). Cameras with
// OpenCV distortion carry only their radial k1/k2 as rd3/rd5 (same r^3, r^5 form).
void from_core(const Camera& camera, uint64_t frame, int64_t capture_ns, bool tracked,
               wire::Owned<studio_CameraCalibration>& out);

// CameraImage holding `data` (JPEG bytes or raw RGB8).
void from_core(const std::string& camera_id, uint64_t frame, int64_t capture_ns, int width,
               int height, bool jpeg, const std::vector<uint8_t>& data,
               wire::Owned<studio_CameraImage>& out);

struct CameraStateCore {
  std::string camera_id;
  uint64_t frame = 0;
  int64_t capture_ns = 0;
  std::vector<Feature> features;
  double fps = 0;
  uint64_t drops = 0;
  bool recording = false;
  std::string take;  // pending or recording take ("" = none)
  enum class Run { kStopped, kStreaming, kRecording, kError } state = Run::kStopped;
  std::string error;
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

}  // namespace studio::capture::node

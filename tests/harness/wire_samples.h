#pragma once
// Deterministic, valid samples of every topic type for tests and the wire peer, and a field-wise
// equality that includes sequence contents. fill(sample, seed): different seeds give different
// contents (and, for keyed types, the id "<prefix><seed % 4>").

#include "wire/sample.h"

namespace studio::testing {

void fill(studio_CameraCalibration& s, int seed);
void fill(studio_AlphaMask& s, int seed);  // MASK_RUNS encoding
void fill(studio_CameraImage& s, int seed);
void fill(studio_CameraState& s, int seed);
void fill(studio_CameraControl& s, int seed);
void fill(studio_CaptureCommand& s, int seed);
void fill(studio_SegmentSet& s, int seed);
void fill(studio_ActorMesh& s, int seed);
void fill(studio_HeadPose& s, int seed);
void fill(studio_SceneNode& s, int seed);
void fill(studio_SceneCommand& s, int seed);
void fill(studio_ProjectorCalibration& s, int seed);
void fill(studio_ServiceStatus& s, int seed);
void fill(studio_SceneState& s, int seed);
void fill(studio_ProjectorMask& s, int seed);
void fill(studio_ProjectorFrame& s, int seed);
void fill(studio_ImageRequest& s, int seed);
void fill(studio_ImageReply& s, int seed);

bool same(const studio_CameraCalibration& a, const studio_CameraCalibration& b);
bool same(const studio_AlphaMask& a, const studio_AlphaMask& b);
bool same(const studio_CameraImage& a, const studio_CameraImage& b);
bool same(const studio_CameraState& a, const studio_CameraState& b);
bool same(const studio_CameraControl& a, const studio_CameraControl& b);
bool same(const studio_CaptureCommand& a, const studio_CaptureCommand& b);
bool same(const studio_SegmentSet& a, const studio_SegmentSet& b);
bool same(const studio_ActorMesh& a, const studio_ActorMesh& b);
bool same(const studio_HeadPose& a, const studio_HeadPose& b);
bool same(const studio_SceneNode& a, const studio_SceneNode& b);
bool same(const studio_SceneCommand& a, const studio_SceneCommand& b);
bool same(const studio_ProjectorCalibration& a, const studio_ProjectorCalibration& b);
bool same(const studio_ServiceStatus& a, const studio_ServiceStatus& b);
bool same(const studio_SceneState& a, const studio_SceneState& b);
bool same(const studio_ProjectorMask& a, const studio_ProjectorMask& b);
bool same(const studio_ProjectorFrame& a, const studio_ProjectorFrame& b);
bool same(const studio_ImageRequest& a, const studio_ImageRequest& b);
bool same(const studio_ImageReply& a, const studio_ImageReply& b);

template <wire::WireType T>
wire::Owned<T> make(int seed) {
  wire::Owned<T> s;
  fill(*s, seed);
  return s;
}

}  // namespace studio::testing

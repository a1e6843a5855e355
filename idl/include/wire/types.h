#pragma once
// The wire contract in one table (DESIGN §3): every topic's name, idlc-generated type,
// descriptor, validator and QoS. TopicTraits<T> maps a generated type (studio_AlphaMask, ...)
// to its row; qos_for() (wire/qos.h) builds the DDS QoS from the row, so QoS lives in exactly
// one place: kTopicTable in idl/src/types.cc.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "studio.h"  // idlc output for idl/studio.idl (C structs + descriptors)

namespace studio::wire {

enum class TopicId : uint8_t {
  camera_calibration,
  camera_mask,
  camera_image,
  camera_state,
  camera_control,
  capture_command,
  actor_segments,
  actor_mesh,
  actor_head,
  scene_node,
  scene_command,
  projector_calibration,
  service_status,
  scene_state,
  projector_mask,
  projector_frame,
  image_request,
  image_reply,
};
inline constexpr std::size_t kTopicCount = 18;

// Why a received sample was rejected (counted per reason by every Reader).
enum class Reject : uint8_t {
  bad_id,        // empty or unterminated key / identifier
  bad_size,      // dimensions or sequence lengths inconsistent with the header fields
  out_of_range,  // enum, index or value outside its valid range
  non_finite,    // NaN or infinity where a finite number is required
  bad_runs,      // mask runs / hull intervals unsorted, overlapping or outside the image/column
};
inline constexpr std::size_t kRejectReasons = 5;
std::string_view reject_name(Reject reason);

// nullopt = the sample may be passed on. Never throws, never reads out of bounds of the sample's
// own sequences.
using Verdict = std::optional<Reject>;

struct TopicRow {
  TopicId id;
  const dds_topic_descriptor_t* descriptor;
  std::size_t sample_size;
  Verdict (*validate)(const void* sample);  // the type's validator
  const char* name;                         // DDS topic name, e.g. "studio/camera/mask"
  bool reliable;                            // else best-effort
  bool transient_local;                     // else volatile
  int32_t depth;                            // keep-last depth (per instance)
  int32_t liveliness_lease_s;               // 0 = infinite (no liveliness contract)
};

const TopicRow& topic_row(TopicId id);
std::span<const TopicRow> topic_table();

// Validators, one per topic type (idl/src/validate.cc).
Verdict validate(const studio_CameraCalibration& s);
Verdict validate(const studio_AlphaMask& s);
Verdict validate(const studio_CameraImage& s);
Verdict validate(const studio_CameraState& s);
Verdict validate(const studio_CameraControl& s);
Verdict validate(const studio_CaptureCommand& s);
Verdict validate(const studio_SegmentSet& s);
Verdict validate(const studio_ActorMesh& s);
Verdict validate(const studio_HeadPose& s);
Verdict validate(const studio_SceneNode& s);
Verdict validate(const studio_SceneCommand& s);
Verdict validate(const studio_ProjectorCalibration& s);
Verdict validate(const studio_ServiceStatus& s);
Verdict validate(const studio_SceneState& s);
Verdict validate(const studio_ProjectorMask& s);
Verdict validate(const studio_ProjectorFrame& s);
Verdict validate(const studio_ImageRequest& s);
Verdict validate(const studio_ImageReply& s);

template <class T>
struct TopicTraits;  // specialised below for every topic type only

#define STUDIO_WIRE_TOPIC(Type, Id)                                                     \
  template <>                                                                           \
  struct TopicTraits<studio_##Type> {                                                   \
    static constexpr TopicId id = TopicId::Id;                                          \
    static const TopicRow& row() { return topic_row(id); }                              \
    static const char* name() { return row().name; }                                    \
    static const dds_topic_descriptor_t* descriptor() { return &studio_##Type##_desc; } \
  };
STUDIO_WIRE_TOPIC(CameraCalibration, camera_calibration)
STUDIO_WIRE_TOPIC(AlphaMask, camera_mask)
STUDIO_WIRE_TOPIC(CameraImage, camera_image)
STUDIO_WIRE_TOPIC(CameraState, camera_state)
STUDIO_WIRE_TOPIC(CameraControl, camera_control)
STUDIO_WIRE_TOPIC(CaptureCommand, capture_command)
STUDIO_WIRE_TOPIC(SegmentSet, actor_segments)
STUDIO_WIRE_TOPIC(ActorMesh, actor_mesh)
STUDIO_WIRE_TOPIC(HeadPose, actor_head)
STUDIO_WIRE_TOPIC(SceneNode, scene_node)
STUDIO_WIRE_TOPIC(SceneCommand, scene_command)
STUDIO_WIRE_TOPIC(ProjectorCalibration, projector_calibration)
STUDIO_WIRE_TOPIC(ServiceStatus, service_status)
STUDIO_WIRE_TOPIC(SceneState, scene_state)
STUDIO_WIRE_TOPIC(ProjectorMask, projector_mask)
STUDIO_WIRE_TOPIC(ProjectorFrame, projector_frame)
STUDIO_WIRE_TOPIC(ImageRequest, image_request)
STUDIO_WIRE_TOPIC(ImageReply, image_reply)
#undef STUDIO_WIRE_TOPIC

template <class T>
concept WireType = requires {
  TopicTraits<T>::id;
};

}  // namespace studio::wire

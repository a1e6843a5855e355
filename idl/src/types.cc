// The DESIGN §3 table: topic names, types, validators and QoS, in one place.

#include "wire/types.h"

#include <array>
#include <stdexcept>

namespace studio::wire {
namespace {

template <class T>
Verdict erased(const void* sample) {
  return validate(*static_cast<const T*>(sample));
}

#define R(Id, Type)                                                                     \
  TopicId::Id, &studio_##Type##_desc, sizeof(studio_##Type), &erased<studio_##Type>
constexpr bool kRel = true, kBE = false;   // reliable / best-effort
constexpr bool kTL = true, kVol = false;   // transient-local / volatile

// Columns after the row: DDS topic name, reliability, durability, keep-last depth (per instance),
// liveliness lease in seconds (0 = none).
// clang-format off
constexpr std::array<TopicRow, kTopicCount> kTopicTable{{
{R(camera_calibration, CameraCalibration),       "studio/camera/calibration",    kRel, kTL,  1,  0},
{R(camera_mask, AlphaMask),                      "studio/camera/mask",           kBE,  kVol, 1,  0},
{R(camera_image, CameraImage),                   "studio/camera/image",          kBE,  kVol, 1,  0},
{R(camera_state, CameraState),                   "studio/camera/state",          kRel, kTL,  1,  0},
{R(camera_control, CameraControl),               "studio/camera/control",        kRel, kVol, 8,  0},
{R(capture_command, CaptureCommand),             "studio/capture/command",       kRel, kTL,  1,  0},
{R(actor_segments, SegmentSet),                  "studio/actor/segments",        kBE,  kVol, 1,  0},
{R(actor_mesh, ActorMesh),                       "studio/actor/mesh",            kRel, kVol, 1,  0},
{R(actor_head, HeadPose),                        "studio/actor/head",            kBE,  kVol, 1,  0},
{R(scene_node, SceneNode),                       "studio/scene/node",            kRel, kTL,  1,  0},
{R(scene_command, SceneCommand),                 "studio/scene/command",         kRel, kVol, 32, 0},
{R(projector_calibration, ProjectorCalibration), "studio/projector/calibration", kRel, kTL,  1,  0},
{R(service_status, ServiceStatus),               "studio/service/status",        kBE,  kVol, 1,  3},
{R(scene_state, SceneState),                     "studio/scene/state",           kRel, kTL,  1,  0},
{R(projector_mask, ProjectorMask),               "studio/projector/mask",        kBE,  kVol, 1,  0},
{R(projector_frame, ProjectorFrame),             "studio/projector/frame",       kRel, kVol, 1,  0},
{R(image_request, ImageRequest),                 "studio/camera/image_request",  kRel, kVol, 32, 0},
{R(image_reply, ImageReply),                     "studio/camera/image_reply",    kRel, kVol, 4,  0},
}};
// clang-format on
#undef R

constexpr bool table_in_enum_order() {
  for (std::size_t i = 0; i < kTopicTable.size(); ++i)
    if (static_cast<std::size_t>(kTopicTable[i].id) != i) return false;
  return true;
}
static_assert(table_in_enum_order(), "kTopicTable rows must follow TopicId order");

}  // namespace

const TopicRow& topic_row(TopicId id) {
  const auto i = static_cast<std::size_t>(id);
  if (i >= kTopicTable.size()) throw std::out_of_range("wire::topic_row: bad TopicId");
  return kTopicTable[i];
}

std::span<const TopicRow> topic_table() { return kTopicTable; }

std::string_view reject_name(Reject reason) {
  switch (reason) {
    case Reject::bad_id:
      return "bad_id";
    case Reject::bad_size:
      return "bad_size";
    case Reject::out_of_range:
      return "out_of_range";
    case Reject::non_finite:
      return "non_finite";
    case Reject::bad_runs:
      return "bad_runs";
  }
  return "unknown";
}

}  // namespace studio::wire

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

#define ROW(Id, Name, Type) TopicId::Id, Name, &studio_##Type##_desc, sizeof(studio_##Type), &erased<studio_##Type>

//                                                                        reliable  transient  depth  lease_ms
constexpr std::array<TopicRow, kTopicCount> kTopicTable{{
    {ROW(camera_calibration, "studio/camera/calibration", CameraCalibration),    true,  true,  1,  0},
    {ROW(camera_mask, "studio/camera/mask", AlphaMask),                          false, false, 1,  0},
    {ROW(camera_image, "studio/camera/image", CameraImage),                      false, false, 1,  0},
    {ROW(camera_state, "studio/camera/state", CameraState),                      true,  true,  1,  0},
    {ROW(camera_control, "studio/camera/control", CameraControl),                true,  false, 8,  0},
    {ROW(capture_command, "studio/capture/command", CaptureCommand),             true,  true,  1,  0},
    {ROW(actor_segments, "studio/actor/segments", SegmentSet),                   false, false, 1,  0},
    {ROW(actor_mesh, "studio/actor/mesh", ActorMesh),                            true,  false, 1,  0},
    {ROW(actor_head, "studio/actor/head", HeadPose),                             false, false, 1,  0},
    {ROW(scene_node, "studio/scene/node", SceneNode),                            true,  true,  1,  0},
    {ROW(scene_command, "studio/scene/command", SceneCommand),                   true,  false, 32, 0},
    {ROW(projector_calibration, "studio/projector/calibration", ProjectorCalibration), true, true, 1, 0},
    {ROW(service_status, "studio/service/status", ServiceStatus),                false, false, 1,  3000},
}};
#undef ROW

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
    case Reject::bad_id: return "bad_id";
    case Reject::bad_size: return "bad_size";
    case Reject::out_of_range: return "out_of_range";
    case Reject::non_finite: return "non_finite";
    case Reject::bad_runs: return "bad_runs";
  }
  return "unknown";
}

}  // namespace studio::wire

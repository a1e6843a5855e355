#pragma once
// The probe's figures from what it recorded (collected.h), as one JSON object, and the latency
// histogram (OpenCV PNG). Definitions (probe.h has the timeline):
//   fps            actor meshes per second reaching the projector (distinct mesh frames in
//                  studio/projector/frame, the slowest projector); without projector frames, frames
//                  of the window whose actor mesh reached the probe (hull_fps, always reported)
//   latency_ms     capture → first projector frame rendered with that mesh (motion to photon;
//                  without projector frames: capture → mesh and head both delivered),
//                  {p50, p95, p99, max, mean, n}, with `stages` (capture→mask, mask→segments,
//                  segments→mesh, segments→head, mesh→projector frame) and the end-to-end variants
//   lit_actor_px   projector light on the true actor at display time, summed over the scored
//                  frames (projector_report.h), with lit_actor_detail and `projector`
//   hull_iou       mean over scored frames of the mean over cameras of IoU(live mesh, true mask)
//   head_error_m   RMS distance of the head updates of the window to the true head
//   masks_lost     cameras × frames of the window − masks that reached the probe (a frame the
//                  camera never delivered counts for every camera that lacks it)
//   per_service    rate (studio/service/status), CPU % of one core and RSS (from /proc), the
//                  counters' increase over the window
//   held_back_by   the first stage whose rate is below 95 % of the camera rate, and the stage
//                  with the largest p99 latency

#include <string>

#include "collected.h"
#include "probe.h"

namespace studio::demo {

std::string make_report(const ProbeOptions& options, const Collected& collected);

}  // namespace studio::demo

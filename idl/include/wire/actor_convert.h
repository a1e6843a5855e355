#pragma once
// Wire samples of the actor topics <-> core types (DESIGN §2 rule 1), shared by every node that
// sends or receives them:
//   studio/actor/segments  studio_SegmentSet <-> hull::SegmentSet   (hull node writes, tracker and
//                                                                      projector nodes read)
//   studio/actor/head      studio_HeadPose   <-> tracker::HeadPose  (tracker node writes,
//                                                                      projector/scene/preview
//                                                                      read)
// Library `studio_wire_actor` (links studio_wire, studio_hull, studio_tracker: the pure types
// these topics carry), the one conversion of these topics. As in wire/convert.h, the key and
// `frame` are the caller's; these convert the payload (HeadPose's capture_ns is part of the core
// value and is converted).
//
// Wire SegmentSet layout (idl/studio.idl): nu x nv columns over [box_min, box_max] (float),
// column c = i + j*nu holds pairs intervals[2k], intervals[2k+1] for k in
// [interval_start[c], interval_start[c+1]), along `axis` — exactly hull::GridSpec (cells_u = nu
// along (axis+1)%3, cells_v = nv along (axis+2)%3) and SegmentSet's compressed rows. The box
// travels as float: a round trip moves the box corners by < 1e-7 relative (intervals are float
// in both).

#include "core/error.h"
#include "hull/segment_set.h"
#include "studio.h"
#include "tracker/head_tracker.h"

namespace studio::wire {

// SegmentSet payload → hull::SegmentSet. Samples from a wire::Reader passed the validator
// already (sizes, order, range); this still checks everything it relies on and returns one line
// instead of trusting it. Zero-length intervals are dropped and touching ones merged (the wire
// allows both; hull::SegmentSet does not).
Expected<hull::SegmentSet> to_core(const studio_SegmentSet& sample);
// hull::SegmentSet → payload (nu, nv, box, axis, interval_start, intervals). The set must be
// valid() (programming error otherwise: std::invalid_argument).
void from_core(const hull::SegmentSet& set, studio_SegmentSet& sample);

// HeadPose → tracker::HeadPose (position, velocity, confidence, capture_ns; actor_id = 0, the
// wire's actor_id string is the caller's). Fails for non-finite values or confidence outside
// [0, 1].
Expected<tracker::HeadPose> to_core(const studio_HeadPose& sample);
// tracker::HeadPose → payload (position, velocity, confidence clamped to [0, 1], capture_ns).
void from_core(const tracker::HeadPose& pose, studio_HeadPose& sample);

}  // namespace studio::wire

#pragma once
// The tracker service node (issue 6 item 3): studio/actor/segments (SegmentSet) in,
// studio/actor/head (HeadPose) out.
//
// One worker thread waits on a WaitSet holding the segments reader and a guard condition (stop).
// For each valid SegmentSet: to_core → rasterise → HeadSearch::find. The hull publishes each
// actor (connected component) of a frame as its own SegmentSet, so the heads of the sets of one
// frame (same frame and capture_ns) arriving within gather_ms of the first are gathered; then
// one HeadTracker::update at that capture_ns → the primary head is published under `actor_id`
// with the source's frame and capture_ns (and, with publish_tracks, every live track as
// <actor_id>/<track id>). A set of that frame arriving after the window is a separate update
// (counter late_segment_sets). An empty
// hull (or no head in it) is a frame without detections: the tracker coasts, its confidence
// decays by coast_decay per frame and reaches 0 once the track is dropped after max_missed frames
// (the fallback pose: last head position, zero velocity, confidence 0).
//
// Keep-alive: when no SegmentSet arrives for 1/publish_rate seconds, the last published pose is
// published again, coasting: each tick advances the position by the velocity over the tick and
// multiplies velocity and confidence by coast_decay; after max_missed ticks confidence and
// velocity are 0 and the position stays. Keep-alive samples carry the source's last frame and
// capture_ns = last capture_ns + the time elapsed since that sample arrived (the instant the pose
// is predicted for, on the source's clock). Keep-alives never enter the tracker, so the next real
// frame is filtered against the last real one.
//
// Runs on runtime::ServiceLoop (runtime/service_loop.h). Metrics: counters segment_sets_in,
// heads_out, empty_hulls, keepalives, late_segment_sets and rejected (the total of
// rejected_malformed, the reader's validator rejections, and rejected_to_core, SegmentSets the
// hull library refuses); latency = publish time − capture_ns of real frames (includes the gather
// window). Status DEGRADED while no head is tracked.

#include <memory>

#include "runtime/service.h"
#include "tracker_config.h"

namespace studio::tracker::node {

// Builds the node (options validated) — exposed for tests that host the node in-process.
Expected<std::unique_ptr<runtime::Node>> make_tracker_node(NodeOptions options,
                                                           runtime::NodeContext& context);

// service_main's definition of the tracker service (name "tracker").
runtime::ServiceDefinition service_definition();

}  // namespace studio::tracker::node

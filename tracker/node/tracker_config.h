#pragma once
// Configuration of the tracker node (studio-tracker --config tracker.yaml). The common service
// keys (instance, domain, dds_config, status_period, log) are read by runtime::service_main;
// these are the tracker's own, read strictly (unknown keys, wrong types and out-of-range values
// are one line "tracker.yaml:LINE: field: problem"):
//
//   actor_id: actor        # key of the published studio/actor/head sample (the primary head)
//   publish_tracks: false  # also publish every live track as <actor_id>/<track id>
//   publish_rate: 10       # Hz: keep-alive when no SegmentSet arrives (0.5 .. 1000)
//   gather_ms: 2           # the hull publishes each actor of a frame as its own SegmentSet: sets
//                          # of one frame arriving within this window are one tracker update
//   search:                # head finder, TCSVT 2004 §IV-D (tracker/head_search.h)
//     head_box: [0.22, 0.24, 0.22]   # V2, metres
//     outer_box: [0.40, 0.64, 0.40]  # V1 ⊇ V2, metres
//     exclude_below: true            # leave V1 under V2 (neck, shoulders) out
//     head_diameter: 0.20            # reference head for confidence 1
//     min_confidence: 0.3
//     suppression_radius: 0.45
//     max_heads: 4
//     refine_radius: 0.11
//     refine_iterations: 6
//   filter:                # per-track constant-velocity Kalman filter (tracker/head_tracker.h)
//     measurement_sigma: 0.01
//     acceleration_sigma: 2.0
//     gate: 0.5
//     max_missed: 25       # frames (or keep-alive ticks) a lost head coasts before confidence 0
//     coast_decay: 0.8     # confidence (and velocity) factor per missed frame
//     rest_position: [0, 1.7, 0]

#include <string>

#include "core/error.h"
#include "tracker/head_search.h"
#include "tracker/head_tracker.h"
#include "yaml_io/node.h"

namespace studio::tracker::node {

struct NodeOptions {
  std::string actor_id = "actor";
  bool publish_tracks = false;
  double publish_rate = 10;
  double gather_ms = 2;
  HeadSearchOptions search;
  HeadTrackerOptions filter;

  Expected<void> validate() const;
};

// Reads (and consumes) the tracker keys from the service config; the caller finishes the map.
Expected<NodeOptions> read_node_options(yaml::MapReader& config);

// The keys above, for --help.
extern const char* const kConfigHelp;

}  // namespace studio::tracker::node

#include "tracker_config.h"

#include <cmath>

#include "yaml_io/options.h"

namespace studio::tracker::node {
namespace {

Expected<Eigen::Vector3d> parse_vec3(const yaml::Node& n) {
  auto v = n.as_doubles(3);
  if (!v) return std::unexpected(v.error());
  return Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
}

const yaml::Schema<HeadSearchOptions>& search_schema() {
  static const yaml::Schema<HeadSearchOptions> schema{
      yaml::field("head_box", &HeadSearchOptions::head_box, parse_vec3),
      yaml::field("outer_box", &HeadSearchOptions::outer_box, parse_vec3),
      yaml::field("exclude_below", &HeadSearchOptions::exclude_below),
      yaml::field("head_diameter", &HeadSearchOptions::head_diameter).range(0.05, 1.0),
      yaml::field("min_confidence", &HeadSearchOptions::min_confidence).range(0.001, 1),
      yaml::field("suppression_radius", &HeadSearchOptions::suppression_radius).range(0, 10),
      yaml::field("max_heads", &HeadSearchOptions::max_heads).range(1, 64),
      yaml::field("refine_radius", &HeadSearchOptions::refine_radius).range(0, 1),
      yaml::field("refine_iterations", &HeadSearchOptions::refine_iterations).range(0, 100),
  };
  return schema;
}

const yaml::Schema<HeadTrackerOptions>& filter_schema() {
  static const yaml::Schema<HeadTrackerOptions> schema{
      yaml::field("measurement_sigma", &HeadTrackerOptions::measurement_sigma).range(1e-6, 1),
      yaml::field("acceleration_sigma", &HeadTrackerOptions::acceleration_sigma).range(1e-6, 1000),
      yaml::field("gate", &HeadTrackerOptions::gate).range(1e-3, 10),
      yaml::field("max_missed", &HeadTrackerOptions::max_missed).range(0, 100000),
      yaml::field("coast_decay", &HeadTrackerOptions::coast_decay).range(0, 1),
      yaml::field("rest_position", &HeadTrackerOptions::rest_position, parse_vec3),
  };
  return schema;
}

// A number in [lo, hi]; out of range: "expected <what>".
auto number_in(double lo, double hi, std::string what) {
  return [lo, hi, what](const yaml::Node& n) -> Expected<double> {
    auto v = n.as_double();
    if (v && !(*v >= lo && *v <= hi)) return n.fail("expected " + what);
    return v;
  };
}

}  // namespace

const char* const kConfigHelp =
    "  actor_id: NAME         key of the published studio/actor/head sample, the primary head\n"
    "                         (default actor; 1..50 characters)\n"
    "  publish_tracks: BOOL   also publish every live track as NAME/<track id> (default false)\n"
    "  publish_rate: HZ       keep-alive rate when no SegmentSet arrives: the last pose coasts\n"
    "                         with decaying confidence, 0 once lost (0.5..1000, default 10)\n"
    "  gather_ms: MS          SegmentSets of one frame (one per actor) arriving within this\n"
    "                         window of the first are one tracker update (0..100, default 2)\n"
    "  search:                head finder (two-box template, TCSVT 2004 IV-D), all optional:\n"
    "    head_box: [X, Y, Z]       inner box V2, metres (default [0.22, 0.24, 0.22])\n"
    "    outer_box: [X, Y, Z]      outer box V1, contains V2 (default [0.40, 0.64, 0.40])\n"
    "    exclude_below: BOOL       leave V1 under the head out (default true)\n"
    "    head_diameter: M          reference head scoring confidence 1 (default 0.20)\n"
    "    min_confidence: C         weakest head reported (default 0.3)\n"
    "    suppression_radius: M     one head per actor within this radius (default 0.45)\n"
    "    max_heads: N              heads searched per frame, 1..64 (default 4)\n"
    "    refine_radius: M          sub-voxel mean-shift kernel, 0 = off (default 0.11)\n"
    "    refine_iterations: N      (default 6)\n"
    "  filter:                per-track constant-velocity Kalman filter, all optional:\n"
    "    measurement_sigma: M      detection noise per axis (default 0.01)\n"
    "    acceleration_sigma: M/S2  white-noise acceleration (default 2.0)\n"
    "    gate: M                   association distance (default 0.5)\n"
    "    max_missed: N             frames/ticks a lost head coasts (default 25)\n"
    "    coast_decay: F            confidence and velocity factor per miss (default 0.8)\n"
    "    rest_position: [X, Y, Z]  eye point before any head was seen (default [0, 1.7, 0])\n";

Expected<void> NodeOptions::validate() const {
  if (actor_id.empty() || actor_id.size() > 50)
    return fail("actor_id: expected a name of 1..50 characters");
  if (!(publish_rate >= 0.5 && publish_rate <= 1000))
    return fail("publish_rate: expected Hz in 0.5..1000");
  if (!(gather_ms >= 0 && gather_ms <= 100)) return fail("gather_ms: expected 0..100 ms");
  if (auto ok = search.validate(); !ok) return ok;
  return filter.validate();
}

Expected<NodeOptions> read_node_options(yaml::MapReader& config) {
  static const yaml::Schema<NodeOptions> schema{
      yaml::field("actor_id", &NodeOptions::actor_id,
                  [](const yaml::Node& n) -> Expected<std::string> {
                    auto v = n.as_string();
                    if (v && (v->empty() || v->size() > 50))
                      return n.fail("expected a name of 1..50 characters");
                    return v;
                  }),
      yaml::field("publish_tracks", &NodeOptions::publish_tracks),
      yaml::field("publish_rate", &NodeOptions::publish_rate,
                  number_in(0.5, 1000, "Hz in 0.5..1000")),
      yaml::field("gather_ms", &NodeOptions::gather_ms, number_in(0, 100, "0..100 ms")),
      yaml::field("search", &NodeOptions::search, search_schema()),
      yaml::field("filter", &NodeOptions::filter, filter_schema()),
  };
  return schema.read_fields(config);
}

}  // namespace studio::tracker::node

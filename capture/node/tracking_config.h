#pragma once
// The `tracking:` section of a camera in capture.yaml (capture_config.h): a Free-D tracked
// camera (capture/freed_listener.h).
//
//   tracking:
//     freed: {port: 40000, bind: 0.0.0.0, id: 1, shared: false, group: ""}
//     world_from_tracker: {R: [9 row-major], t: [3]}   # default identity
//     head_from_lens: {R: [9], t: [3]}                 # default identity
//     lens: {K: [9], radial: [rd3, rd5]}               # a fixed lens, or
//     lens_table: FILE.yaml                            # zoom/focus -> intrinsics
//     delay_frames: 0                                  # tracker data lags video by N frames
//
// Lens table file: {width: W, height: H, feature_scale: 1,
//                   samples: [{zoom, focus, fx, fy, cx, cy, rd3, rd5}, ...]}
// (capture/freed.h LensTable: linear in focus within a zoom level, linear in zoom between
// levels). Every camera on one (bind, port) shares one listener; ids must differ.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "capture/freed.h"
#include "capture/freed_listener.h"
#include "yaml_io/node.h"

namespace studio::capture::node {

extern const char kTrackingHelp[];

struct TrackingKeys {
  FreeDListenerOptions listener;  // bind, port, shared, group (clock set later)
  int freed_id = 0;
  Rigid3 world_from_tracker, head_from_lens;
  std::optional<LensTable> lens;        // lens: or lens_table:
  int lens_width = 0, lens_height = 0;  // from the lens table file (0: the source's size)
  int delay_frames = 0;
};

// Reads the `tracking:` mapping; errors "file:line: field: problem".
Expected<TrackingKeys> read_tracking(const yaml::Node& node);

// A lens table file (format above, plus feature_scale: the table's zoom/focus counts per unit of
// the GenICam Zoom/Focus features, for fixed cameras; default 1).
struct LensTableFile {
  LensTable table;
  int width = 0, height = 0;
  double feature_scale = 1;
};
Expected<LensTableFile> read_lens_table(const std::string& path);

// One listener per (bind, port), shared by the cameras configured on it.
class Listeners {
 public:
  Expected<std::shared_ptr<FreeDListener>> get(FreeDListenerOptions options);

 private:
  std::map<std::pair<std::string, uint16_t>, std::shared_ptr<FreeDListener>> by_port_;
};

// Wraps `inner` in a TrackedSource. `width`/`height`: the source's image size when known (0
// otherwise); `default_lens`: the source's own intrinsics when it has them (simulated camera).
Expected<std::unique_ptr<TrackedSource>> make_tracked_source(
    std::unique_ptr<FrameSource> inner, const TrackingKeys& keys, const std::string& camera_id,
    int width, int height, const std::optional<Camera>& default_lens, const FrameClock& clock,
    Listeners& listeners);

}  // namespace studio::capture::node

#pragma once
// Configuration of the scene server (studio-scene --config scene.yaml). The common service keys
// (instance, domain, dds_config, status_period, log) are read by runtime::service_main; these
// are the server's own, read strictly (unknown keys, wrong types and out-of-range values are one
// line "scene.yaml:LINE: field: problem"). scene/node/scene.example.yaml documents every key.
//
//   clock:                  # the studio clock (DESIGN §5): frame = (now - epoch_ns) / period
//     fps: 25               # or period_ns: 40000000 (not both)
//     epoch_ns: 0           # CLOCK_REALTIME ns of frame 0
//     source: studio        # studio: the server ticks itself every studio frame (animations are
//                           #   evaluated and published per frame); commands: only SCENE_TICK
//                           #   commands evaluate (a replay or a director stepping frames)
//   scene: scene.yaml       # the scene at first start (no persisted state): a scene file or a set
//   state_dir: /var/lib/studio/scene   # persisted scene + animation clocks; absent = not persisted
//   persist_interval: 1.0   # seconds: the longest time a tick-only change stays unpersisted
//   command_queue: 16384    # SceneCommand samples the server's reader keeps while it is busy

#include <cstdint>
#include <string>

#include "core/error.h"
#include "yaml_io/node.h"

namespace studio::scene::node {

enum class ClockSource { studio, commands };

struct NodeOptions {
  int64_t period_ns = 40'000'000;  // 25 fps, the paper's
  int64_t epoch_ns = 0;
  ClockSource clock_source = ClockSource::studio;
  std::string scene_file;         // "" = start empty
  std::string base_dir;           // the config's folder: relative LOAD_SET paths start here
  std::string state_dir;          // "" = no persistence
  double persist_interval = 1.0;  // seconds
  int32_t command_queue = 16384;

  double frame_period() const { return double(period_ns) / 1e9; }
  // The studio frame at realtime `now_ns` (DESIGN §5); negative before the epoch.
  int64_t frame_at(int64_t now_ns) const;
  Expected<void> validate() const;
};

// `path` relative to `base_dir` (absolute paths unchanged).
std::string resolve_path(const std::string& base_dir, const std::string& path);

// Reads (and consumes) the scene server keys from the service config; the caller finishes the map.
Expected<NodeOptions> read_node_options(yaml::MapReader& config);

// The keys above, for --help.
extern const char* const kConfigHelp;

}  // namespace studio::scene::node

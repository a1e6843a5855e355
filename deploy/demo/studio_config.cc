#include "studio_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>

namespace studio::demo {

bool StudioConfig::all_simulated() const {
  return std::all_of(simulated.begin(), simulated.end(), [](bool s) { return s; });
}

namespace {

Expected<capture::FrameClock> read_clock(const YAML::Node& root, const std::string& file) {
  capture::FrameClock clock;  // studio-capture's defaults: 25 fps, epoch 0
  const YAML::Node c = root["clock"];
  if (!c) return clock;
  if (!c.IsMap()) return fail(file + ": clock: expected a mapping");
  if (c["fps"] && c["period_ns"]) return fail(file + ": clock: give fps or period_ns, not both");
  if (c["fps"]) {
    const double fps = c["fps"].as<double>();
    if (!(fps >= 0.1 && fps <= 1000)) return fail(file + ": clock: fps must be in [0.1, 1000]");
    clock.period_ns = int64_t(1e9 / fps + 0.5);  // as capture_config.cc rounds it
  }
  if (c["period_ns"]) clock.period_ns = c["period_ns"].as<int64_t>();
  if (c["epoch_ns"]) clock.epoch_ns = c["epoch_ns"].as<int64_t>();
  if (clock.period_ns <= 0) return fail(file + ": clock: period must be positive");
  return clock;
}

}  // namespace

Expected<StudioConfig> read_studio_config(const std::vector<std::string>& capture_configs) {
  if (capture_configs.empty()) return fail("no capture config given");
  StudioConfig out;
  bool have_clock = false;
  for (const std::string& file : capture_configs) {
    YAML::Node root;
    try {
      root = YAML::LoadFile(file);
    } catch (const std::exception& e) {
      return fail(file + ": " + e.what());
    }
    try {
      if (!root.IsMap()) return fail(file + ": expected a mapping");
      auto clock = read_clock(root, file);
      if (!clock) return std::unexpected(clock.error());
      if (have_clock &&
          (clock->period_ns != out.clock.period_ns || clock->epoch_ns != out.clock.epoch_ns))
        return fail(file +
                    ": clock differs from the other capture configs (DESIGN §5: one "
                    "studio clock)");
      out.clock = *clock;
      have_clock = true;
      const YAML::Node cams = root["cameras"];
      if (!cams || !cams.IsSequence() || cams.size() == 0)
        return fail(file + ": cameras: expected a list");
      for (const auto& cam : cams) {
        const std::string id = cam["id"].as<std::string>();
        if (std::find(out.camera_ids.begin(), out.camera_ids.end(), id) != out.camera_ids.end())
          return fail(file + ": camera " + id + " appears twice");
        out.camera_ids.push_back(id);
        const YAML::Node src = cam["source"];
        out.simulated.push_back(src && src["type"] && src["type"].as<std::string>() == "sim");
      }
    } catch (const YAML::Exception& e) {
      return fail(file + ": " + e.what());
    }
  }
  return out;
}

}  // namespace studio::demo

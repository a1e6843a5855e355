// The keyer service's options, read from its config through core/yaml's schema, and its
// definition for runtime::service_main (keyer_node.h).
#include <algorithm>
#include <set>

#include "keyer/config/keyer_yaml.h"
#include "keyer_node.h"
#include "yaml_io/options.h"

namespace studio::keyer {
namespace {

// `keyer:` holds the options (a mapping; empty = defaults) or names a keyer.yaml.
Expected<KeyerOptions> parse_keyer(const yaml::Node& n) {
  if (n.is_null() || n.is_map()) return read_keyer_options(n);
  if (!n.is_scalar())
    return n.fail("expected the keyer options (a mapping) or the path of a keyer.yaml");
  auto path = n.as_string();
  if (!path) return std::unexpected(path.error());
  return load_keyer_options(yaml::resolve_path(n, *path));
}

Expected<std::vector<std::string>> parse_cameras(const yaml::Node& n) {
  std::vector<std::string> ids;
  if (auto r = yaml::read_value(n, ids, {}); !r) return std::unexpected(r.error());
  if (ids.empty())
    return n.fail("expected at least one camera id (leave the key out to key every camera)");
  std::set<std::string> seen;
  for (const auto& id : ids) {
    if (id.empty() || id.size() > 63) return n.fail("camera ids have 1..63 characters");
    if (!seen.insert(id).second) return n.fail("duplicate camera id " + id);
  }
  return ids;
}

Expected<std::string> parse_folder(const yaml::Node& n) {
  auto path = n.as_string();
  if (!path) return std::unexpected(path.error());
  if (path->empty()) return n.fail("expected a folder");
  return yaml::resolve_path(n, *path);
}

Expected<std::map<std::string, std::string>> parse_plates(const yaml::Node& n) {
  auto entries = n.entries();
  if (!entries) return std::unexpected(entries.error());
  std::map<std::string, std::string> plates;
  for (const auto& [id, file] : *entries) {
    auto path = file.as_string();
    if (!path) return std::unexpected(path.error());
    plates.emplace(id, yaml::resolve_path(file, *path));
  }
  return plates;
}

}  // namespace

Expected<void> KeyerNodeOptions::validate() const {
  if (auto k = keyer.validate(); !k) return k;
  if (max_cameras < 1 || max_cameras > 64) return fail("max_cameras: must be in [1, 64]");
  if (threads < 1 || threads > 16) return fail("threads: must be in [1, 16]");
  if (!plates.empty() && keyer.mode != KeyMode::kDifference)
    return fail("plates: clean plates need the difference key (keyer.key)");
  if (!plate_dir.empty() && keyer.mode != KeyMode::kDifference)
    return fail("plate_dir: clean plates need the difference key (keyer.key)");
  for (const auto& [id, file] : plates)
    if (!cameras.empty() && std::find(cameras.begin(), cameras.end(), id) == cameras.end())
      return fail("plates: camera " + id + " is not in cameras");
  return {};
}

Expected<KeyerNodeOptions> read_keyer_node_options(yaml::MapReader& config) {
  static const yaml::Schema<KeyerNodeOptions> schema{
      yaml::field("keyer", &KeyerNodeOptions::keyer, parse_keyer),
      yaml::field("cameras", &KeyerNodeOptions::cameras, parse_cameras),
      yaml::field("max_cameras", &KeyerNodeOptions::max_cameras).range(1, 64),
      yaml::field("threads", &KeyerNodeOptions::threads).range(1, 16),
      yaml::field("plate_dir", &KeyerNodeOptions::plate_dir, parse_folder),
      yaml::field("plates", &KeyerNodeOptions::plates, parse_plates),
  };
  return schema.read_fields(config);
}

runtime::ServiceDefinition keyer_service_definition() {
  runtime::ServiceDefinition d;
  d.name = "keyer";
  d.summary =
      "Standalone keyer: raw RGB8 camera images in (studio/camera/image), masks out "
      "(studio/camera/mask).";
  d.config_help =
      "  keyer: {...} | FILE       keyer options (keyer.example.yaml): this file's keyer: section "
      "or a file\n"
      "  cameras: [cam0, ...]      camera ids to key (default: every camera seen)\n"
      "  max_cameras: 16           cameras keyed at most when keying every camera seen (1..64)\n"
      "  threads: 1                keying threads (1..16)\n"
      "  plates: {cam0: FILE}      clean plates for the difference key (PNG/JPEG, frame size)\n"
      "  plate_dir: DIR            keep plates captured on command as DIR/<camera>.png, load at "
      "start\n"
      "Clean plate on command: CameraControl feature KeyerPlate, value N averages the next N "
      "frames\n"
      "(0 clears). Only the newest frame per camera waits; older ones are dropped and counted.\n";
  d.create = [](yaml::MapReader& config,
                runtime::NodeContext& ctx) -> Expected<std::unique_ptr<runtime::Node>> {
    auto options = read_keyer_node_options(config);
    if (!options) return std::unexpected(options.error());
    return make_keyer_node(std::move(*options), ctx);
  };
  return d;
}

}  // namespace studio::keyer

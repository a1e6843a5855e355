#include "keyer/config/keyer_yaml.h"

#include "yaml_io/options.h"

namespace studio::keyer {
namespace {

const yaml::Schema<EdgeRefineOptions>& edge_schema() {
  static const yaml::Schema<EdgeRefineOptions> schema{
      yaml::field("threshold", &EdgeRefineOptions::threshold),
      yaml::field("min_contrast", &EdgeRefineOptions::min_contrast),
  };
  return schema;
}

const yaml::Schema<CleanupOptions>& cleanup_schema() {
  static const yaml::Schema<CleanupOptions> schema{
      yaml::field("min_component_area", &CleanupOptions::min_component_area),
      yaml::field("max_hole_area", &CleanupOptions::max_hole_area),
      yaml::field("keep_backing_gaps", &CleanupOptions::keep_backing_gaps),
  };
  return schema;
}

Expected<KeyMode> parse_mode(const yaml::Node& n) {
  auto s = n.as_string();
  if (!s) return std::unexpected(s.error());
  auto mode = parse_key_mode(*s);
  if (!mode) return n.fail(mode.error().message);
  return mode;
}

const yaml::Schema<KeyerOptions>& keyer_schema() {
  static const yaml::Schema<KeyerOptions> schema{
      yaml::field("key", &KeyerOptions::mode, parse_mode),
      yaml::field("gain", &KeyerOptions::gain),
      yaml::field("clip_black", &KeyerOptions::clip_black),
      yaml::field("clip_white", &KeyerOptions::clip_white),
      yaml::field("diff_low", &KeyerOptions::diff_low),
      yaml::field("diff_high", &KeyerOptions::diff_high),
      yaml::field("matte_threshold", &KeyerOptions::matte_threshold),
      yaml::field("edge_refine", &KeyerOptions::edge_refine),
      yaml::field("edge", &KeyerOptions::edge, edge_schema()),
      yaml::field("spill_strength", &KeyerOptions::spill_strength),
      yaml::field("cleanup", &KeyerOptions::cleanup, cleanup_schema()),
  };
  return schema;
}

// The keyer has always named an unknown key in quotes ("unknown key 'shade'"), and its users'
// scripts and tests look for that: the same check as the schema's, with the key quoted.
template <class T>
Expected<void> name_unknown_keys(const yaml::Node& map, const yaml::Schema<T>& schema) {
  if (!map.is_map()) return {};  // the schema says "expected a mapping"
  auto entries = map.entries();
  if (!entries) return std::unexpected(entries.error());
  for (const auto& [key, value] : *entries)
    if (!schema.has_field(key)) return value.fail("unknown key '" + key + "'");
  return {};
}

Expected<void> name_unknown_keys(const yaml::Node& section) {
  if (auto ok = name_unknown_keys(section, keyer_schema()); !ok) return ok;
  auto map = yaml::MapReader::from(section);
  if (!map) return {};
  if (auto edge = map->optional("edge"))
    if (auto ok = name_unknown_keys(*edge, edge_schema()); !ok) return ok;
  if (auto cleanup = map->optional("cleanup"))
    if (auto ok = name_unknown_keys(*cleanup, cleanup_schema()); !ok) return ok;
  return {};
}

Expected<KeyerOptions> read_document(const yaml::Node& root) {
  if (root.is_null()) return KeyerOptions{};
  auto map = yaml::MapReader::from(root);
  if (!map) return root.fail("expected a mapping of keyer options");
  if (auto section = map->optional("keyer")) return read_keyer_options(*section);
  return read_keyer_options(root);
}

}  // namespace

Expected<KeyerOptions> read_keyer_options(const yaml::Node& section) {
  if (section.is_null()) return KeyerOptions{};
  if (auto ok = name_unknown_keys(section); !ok) return std::unexpected(ok.error());
  return keyer_schema().read(section);
}

Expected<KeyerOptions> load_keyer_options(const std::string& path) {
  auto root = yaml::load_file(path);
  if (!root) return std::unexpected(root.error());
  return read_document(*root);
}

}  // namespace studio::keyer

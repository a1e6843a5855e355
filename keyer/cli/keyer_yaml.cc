#include "keyer_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <optional>
#include <sstream>

namespace studio::keyer {
namespace {

std::string where(const std::string& name, const YAML::Node& n) {
  return name + ":" + std::to_string(n.Mark().line + 1);
}

Expected<void> read_float(const std::string& name, const YAML::Node& n, const std::string& key, float& out) {
  try {
    out = n.as<float>();
    return {};
  } catch (const YAML::Exception&) {
    return fail(where(name, n) + ": " + key + ": expected a number");
  }
}

Expected<void> read_int(const std::string& name, const YAML::Node& n, const std::string& key, int& out) {
  try {
    out = n.as<int>();
    return {};
  } catch (const YAML::Exception&) {
    return fail(where(name, n) + ": " + key + ": expected an integer");
  }
}

Expected<void> read_bool(const std::string& name, const YAML::Node& n, const std::string& key,
                         bool& out) {
  try {
    out = n.as<bool>();
    return {};
  } catch (const YAML::Exception&) {
    return fail(where(name, n) + ": " + key + ": expected true or false");
  }
}

// A nested mapping `section:`; field(key, node, "section.key") reads one entry and returns
// nullopt for a key it does not know, which is an error line.
template <class Field>
Expected<void> read_section(const std::string& name, const YAML::Node& v, const std::string& section,
                            Field&& field) {
  if (!v.IsMap()) return fail(where(name, v) + ": " + section + ": expected a mapping");
  for (const auto& c : v) {
    const std::string key = c.first.as<std::string>("");
    const std::optional<Expected<void>> r = field(key, c.second, section + "." + key);
    if (!r) return fail(where(name, c.first) + ": " + section + ": unknown key '" + key + "'");
    if (!*r) return *r;
  }
  return {};
}

}  // namespace

Expected<KeyerOptions> parse_keyer_options(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return fail(name + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
  KeyerOptions o;
  if (!root || root.IsNull()) return o;
  if (!root.IsMap()) return fail(name + ": expected a mapping of keyer options");
  YAML::Node section = root["keyer"] ? root["keyer"] : root;
  if (!section.IsMap()) return fail(where(name, section) + ": keyer: expected a mapping");
  for (const auto& kv : section) {
    const std::string key = kv.first.as<std::string>("");
    const YAML::Node& v = kv.second;
    Expected<void> r;
    if (key == "key") {
      auto mode = v.IsScalar() ? parse_key_mode(v.Scalar()) : fail("key: expected a scalar");
      if (!mode) return fail(where(name, v) + ": " + mode.error().message);
      o.mode = *mode;
    } else if (key == "gain") {
      r = read_float(name, v, key, o.gain);
    } else if (key == "clip_black") {
      r = read_float(name, v, key, o.clip_black);
    } else if (key == "clip_white") {
      r = read_float(name, v, key, o.clip_white);
    } else if (key == "diff_low") {
      r = read_float(name, v, key, o.diff_low);
    } else if (key == "diff_high") {
      r = read_float(name, v, key, o.diff_high);
    } else if (key == "matte_threshold") {
      r = read_float(name, v, key, o.matte_threshold);
    } else if (key == "edge_refine") {
      r = read_bool(name, v, key, o.edge_refine);
    } else if (key == "edge") {
      r = read_section(name, v, key, [&](const std::string& k, const YAML::Node& n,
                                          const std::string& path) -> std::optional<Expected<void>> {
        if (k == "threshold") return read_float(name, n, path, o.edge.threshold);
        if (k == "min_contrast") return read_float(name, n, path, o.edge.min_contrast);
        return std::nullopt;
      });
    } else if (key == "spill_strength") {
      r = read_float(name, v, key, o.spill_strength);
    } else if (key == "cleanup") {
      r = read_section(name, v, key, [&](const std::string& k, const YAML::Node& n,
                                          const std::string& path) -> std::optional<Expected<void>> {
        if (k == "min_component_area") return read_int(name, n, path, o.cleanup.min_component_area);
        if (k == "max_hole_area") return read_int(name, n, path, o.cleanup.max_hole_area);
        if (k == "keep_backing_gaps") return read_bool(name, n, path, o.cleanup.keep_backing_gaps);
        return std::nullopt;
      });
    } else {
      return fail(where(name, kv.first) + ": unknown key '" + key + "'");
    }
    if (!r) return std::unexpected(r.error());
  }
  if (auto ok = o.validate(); !ok) return fail(name + ": " + ok.error().message);
  return o;
}

Expected<KeyerOptions> load_keyer_options(const std::string& path) {
  std::ifstream in(path);
  if (!in) return fail("cannot read config '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_keyer_options(ss.str(), path);
}

}  // namespace studio::keyer

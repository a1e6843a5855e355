#include "keyer_yaml.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
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
      if (!v.IsMap()) return fail(where(name, v) + ": edge: expected a mapping");
      for (const auto& c : v) {
        const std::string ek = c.first.as<std::string>("");
        if (ek == "threshold") {
          r = read_float(name, c.second, "edge.threshold", o.edge.threshold);
        } else if (ek == "min_contrast") {
          r = read_float(name, c.second, "edge.min_contrast", o.edge.min_contrast);
        } else {
          return fail(where(name, c.first) + ": edge: unknown key '" + ek + "'");
        }
        if (!r) return std::unexpected(r.error());
      }
    } else if (key == "spill_strength") {
      r = read_float(name, v, key, o.spill_strength);
    } else if (key == "cleanup") {
      if (!v.IsMap()) return fail(where(name, v) + ": cleanup: expected a mapping");
      for (const auto& c : v) {
        const std::string ck = c.first.as<std::string>("");
        if (ck == "min_component_area") {
          r = read_int(name, c.second, "cleanup.min_component_area", o.cleanup.min_component_area);
        } else if (ck == "max_hole_area") {
          r = read_int(name, c.second, "cleanup.max_hole_area", o.cleanup.max_hole_area);
        } else if (ck == "keep_backing_gaps") {
          r = read_bool(name, c.second, "cleanup.keep_backing_gaps", o.cleanup.keep_backing_gaps);
        } else {
          return fail(where(name, c.first) + ": cleanup: unknown key '" + ck + "'");
        }
        if (!r) return std::unexpected(r.error());
      }
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

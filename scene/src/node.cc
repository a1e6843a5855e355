#include "scene/node.h"

#include <cmath>
#include <numbers>

namespace studio::scene {
namespace {

bool printable(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

bool unit_colour(const auto& c) {
  return c.allFinite() && c.minCoeff() >= 0.0f && c.maxCoeff() <= 1.0f;
}

}  // namespace

Expected<void> Node::validate() const {
  if (id.empty()) return fail("node id is empty");
  if (!printable(id) || id.size() > 256) return fail("node id '" + id + "' is not a printable name of <= 256 bytes");
  if (!printable(parent)) return fail("node '" + id + "': parent id has control characters");
  if (parent == id) return fail("node '" + id + "' is its own parent");
  if (auto ok = local.validate(); !ok) return fail("node '" + id + "': " + ok.error().message);
  switch (kind) {
    case NodeKind::group:
      break;
    case NodeKind::model:
      if (asset.path.empty()) return fail("node '" + id + "': a model needs an asset path");
      break;
    case NodeKind::light:
      if (!unit_colour(light.colour)) return fail("node '" + id + "': light colour must be in [0, 1]");
      if (!std::isfinite(light.intensity) || light.intensity < 0)
        return fail("node '" + id + "': light intensity must be finite and >= 0");
      if (!std::isfinite(light.range) || light.range < 0)
        return fail("node '" + id + "': light range must be finite and >= 0");
      if (!(light.inner_cone >= 0 && light.inner_cone <= light.outer_cone &&
            light.outer_cone <= std::numbers::pi_v<float> / 2 + 1e-6f))
        return fail("node '" + id + "': spot cones must satisfy 0 <= inner <= outer <= pi/2");
      if (static_cast<unsigned>(light.type) > 2) return fail("node '" + id + "': bad light type");
      break;
    case NodeKind::actor:
      if (actor_id.empty()) return fail("node '" + id + "': an actor node needs an actor id");
      break;
    default:
      return fail("node '" + id + "': bad node kind");
  }
  if (!unit_colour(material.colour)) return fail("node '" + id + "': colour must be in [0, 1]");
  return {};
}

const char* to_string(NodeKind kind) {
  switch (kind) {
    case NodeKind::group: return "group";
    case NodeKind::model: return "model";
    case NodeKind::light: return "light";
    case NodeKind::actor: return "actor";
  }
  return "?";
}

const char* to_string(LightType type) {
  switch (type) {
    case LightType::point: return "point";
    case LightType::directional: return "directional";
    case LightType::spot: return "spot";
  }
  return "?";
}

}  // namespace studio::scene

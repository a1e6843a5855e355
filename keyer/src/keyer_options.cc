#include "keyer/keyer_options.h"

#include <cmath>

namespace studio::keyer {

std::string_view key_mode_name(KeyMode mode) {
  switch (mode) {
    case KeyMode::kBlue: return "blue";
    case KeyMode::kGreen: return "green";
    case KeyMode::kDifference: return "difference";
  }
  return "?";
}

Expected<KeyMode> parse_key_mode(std::string_view name) {
  if (name == "blue") return KeyMode::kBlue;
  if (name == "green") return KeyMode::kGreen;
  if (name == "difference") return KeyMode::kDifference;
  return fail("key: expected blue, green or difference, got '" + std::string(name) + "'");
}

Expected<void> KeyerOptions::validate() const {
  auto finite = [](float v) { return std::isfinite(v); };
  if (!finite(gain) || gain <= 0.0f) return fail("gain: must be > 0");
  if (!finite(clip_black) || clip_black < 0.0f) return fail("clip_black: must be >= 0");
  if (!finite(clip_white) || clip_white <= clip_black)
    return fail("clip_white: must be greater than clip_black");
  if (!finite(diff_low) || diff_low < 0.0f) return fail("diff_low: must be >= 0");
  if (!finite(diff_high) || diff_high <= diff_low || diff_high > 255.0f)
    return fail("diff_high: must be in (diff_low, 255]");
  if (!finite(matte_threshold) || matte_threshold <= 0.0f || matte_threshold > 1.0f)
    return fail("matte_threshold: must be in (0, 1]");
  if (!finite(edge.threshold) || edge.threshold <= 0.0f || edge.threshold >= 1.0f)
    return fail("edge.threshold: must be in (0, 1)");
  if (!finite(edge.min_contrast) || edge.min_contrast < 0.0f)
    return fail("edge.min_contrast: must be >= 0");
  if (cleanup.min_component_area < 0) return fail("cleanup.min_component_area: must be >= 0");
  if (cleanup.max_hole_area < 0) return fail("cleanup.max_hole_area: must be >= 0");
  if (!finite(spill_strength) || spill_strength < 0.0f || spill_strength > 1.0f)
    return fail("spill_strength: must be in [0, 1]");
  return {};
}

}  // namespace studio::keyer

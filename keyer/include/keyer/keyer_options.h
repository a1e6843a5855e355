#pragma once
// Options of the keyer (keyer/keyer.h). Every field is a key of keyer.yaml (see
// keyer/keyer.example.yaml, which documents them; keyer/config/keyer_yaml.cc reads it).
//
// Colour-difference key (Vlahos style), for a blue (default) or green backing:
//   excess  = K - max(O1, O2)           K = key channel (B or G), O1, O2 = the other two, in 0..255
//   backing = gain * excess
//   alpha   = 1 - clamp((backing - clip_black) / (clip_white - clip_black), 0, 1)
// so backing <= clip_black is solid actor (alpha 1) and backing >= clip_white is clean backing
// (alpha 0). The binary mask holds the pixels with alpha >= matte_threshold.
// Difference key against a clean plate P (the paper's alternative to the chroma key):
//   diff  = max over channels |I - P|
//   alpha = clamp((diff - diff_low) / (diff_high - diff_low), 0, 1)
// Edge refinement (keyer/edge_refine.h), on by default, then re-decides the pixels on either
// side of each transition of that mask by unmixing their colour between the neighbouring actor
// and backing colours: the binary mask follows the contour where the actor covers
// edge.threshold of a pixel rather than where alpha crosses matte_threshold.
// Clean-up runs on the binary mask's runs, at a cost linear in the number of runs: foreground
// components (8-connected) smaller than min_component_area pixels are removed, then background
// components (4-connected) that do not touch the image border and are at most max_hole_area
// pixels are filled, except (keep_backing_gaps) those that show the clean backing somewhere: a
// pixel with alpha 0 (chroma: backing >= clip_white; difference: diff <= diff_low) is a real gap
// between limbs, not a false hole in the clothes.

#include <string>
#include <string_view>

#include "core/error.h"
#include "keyer/edge_refine.h"

namespace studio::keyer {

enum class KeyMode { kBlue, kGreen, kDifference };

std::string_view key_mode_name(KeyMode mode);
Expected<KeyMode> parse_key_mode(std::string_view name);  // "blue" | "green" | "difference"

struct CleanupOptions {
  int min_component_area = 64;  // pixels; 0 keeps every component
  int max_hole_area = 400;      // pixels; 0 fills nothing
  // Keep holes open when one of their pixels is clean backing (alpha 0). Used by Keyer::key();
  // clean_mask() alone (no image) cannot tell and fills by area only.
  bool keep_backing_gaps = true;
};

struct KeyerOptions {
  KeyMode mode = KeyMode::kBlue;
  // Chroma key.
  float gain = 1.0f;
  float clip_black = 20.0f;   // backing level at and below which alpha = 1
  float clip_white = 100.0f;  // backing level at and above which alpha = 0
  // Difference key.
  float diff_low = 12.0f;     // difference at and below which alpha = 0
  float diff_high = 36.0f;    // difference at and above which alpha = 1
  // Binary mask = alpha >= matte_threshold, in (0, 1].
  float matte_threshold = 0.5f;
  bool edge_refine = true;
  EdgeRefineOptions edge;
  CleanupOptions cleanup;
  // Spill suppression for the preview image: K' = K - spill_strength * max(0, K - max(O1, O2)).
  float spill_strength = 1.0f;  // 0 = off, 1 = full (key channel limited to the larger other)

  // One line naming the first bad field.
  Expected<void> validate() const;
};

// The formulas above, shared by the fast keyer (which tabulates them) and the reference keyer.
inline float chroma_alpha(float excess, const KeyerOptions& o) {
  const float t = (o.gain * excess - o.clip_black) / (o.clip_white - o.clip_black);
  return 1.0f - (t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t);
}
inline float difference_alpha(float diff, const KeyerOptions& o) {
  const float t = (diff - o.diff_low) / (o.diff_high - o.diff_low);
  return t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
}

}  // namespace studio::keyer

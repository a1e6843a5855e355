#pragma once
// The straightforward per-pixel keyer: the formulas of keyer/keyer_options.h evaluated in floating
// point for every pixel into a full-resolution mask, no clean-up. It is the baseline the benchmark
// compares against and the oracle the fast keyer's tests compare with (same binary decision).

#include "core/image.h"
#include "keyer/keyer_options.h"

namespace studio::keyer {

// 255 where alpha >= options.matte_threshold. For KeyMode::kDifference, `plate` (RGB order, the
// frame's size) is required.
Mask reference_key(ImageView<const Rgb8> frame, const KeyerOptions& options,
                   const Image<Rgb8>* plate = nullptr);

}  // namespace studio::keyer

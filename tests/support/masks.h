#pragma once
// Mask comparisons that tests and benchmarks repeat (one copy; tests/support).

#include "core/image.h"
#include "core/run_mask.h"

namespace studio::support {

// Intersection over union |a ∧ b| / |a ∨ b| of the non-zero pixels (1 when both are empty).
// Sizes must match (std::invalid_argument otherwise).
double iou(const Mask& a, const Mask& b);
double iou(const RunMask& a, const RunMask& b);

}  // namespace studio::support

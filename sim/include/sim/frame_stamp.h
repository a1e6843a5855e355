#pragma once
// The frame number stamped into a simulated camera's pixels (a corner code), so that a test can
// check WHICH frame a recorded picture is from by its content, not only by its header
// (issue 17: frame-accurate takes checked against the pixels).
//
// Code: 48 bits in 2 rows of 24 square cells of `cell` px at the image's top-left corner, row
// major, most significant bit first: 40 bits of the frame number (mod 2^40), then an 8-bit check
// (the XOR of the number's 5 bytes, inverted, so an all-black or all-white corner never reads as
// a valid code). A bit is a cell of black (0) or white (255) in every channel; reading samples
// the middle half of each cell and thresholds its mean at 128, so sensor noise of a few grey
// levels and mild blur are harmless.

#include <cstdint>
#include <optional>

#include "core/image.h"

namespace studio::sim {

inline constexpr int kStampColumns = 24, kStampRows = 2;

// Stamps `frame` into `image` (which must be at least 24*cell x 2*cell px).
void stamp_frame(ImageView<Rgb8> image, uint64_t frame, int cell = 4);
// The stamped frame number (mod 2^40), or nullopt when the corner holds no valid code.
std::optional<uint64_t> read_frame_stamp(ImageView<const Rgb8> image, int cell = 4);

}  // namespace studio::sim

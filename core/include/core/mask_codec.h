#pragma once
// The mask codec: RunMask <-> bytes, the form alpha masks travel in from the keyer to the hull.
// The paper run-length encodes each 704x576 mask into ~4000 bytes; the default coding here codes
// each row's transitions relative to the row above and needs a few hundred bytes for an actor.
//
// Byte layout (all integers unsigned LEB128 varints unless noted):
//   byte 0      magic 'M' (0x4D)
//   byte 1      coding: 1 = kRuns, 2 = kRowDelta
//   varint      width   (0 .. kMaxMaskSide)
//   varint      height  (0 .. kMaxMaskSide)
//   payload
// kRuns (byte aligned, row-major): per row, varint n (number of runs), then per run
//   varint gap (begin of the first run, else begin - previous end - 1) and varint (length - 1).
// kRowDelta (bit stream, MSB first, zero padded to a byte): a row is a sorted list of transitions
//   t0 < t1 < ... < t(2n-1) (run i = [t(2i), t(2i+1))). Per row, one bit:
//   0  the row has as many transitions as the row above (row -1 is empty); then per transition
//      the signed delta d = t_i - above_i: '0' for 0, else '1', a sign bit (1 = negative) and
//      Exp-Golomb(0) of |d| - 1;
//   1  explicit row: Exp-Golomb(0) of n, then Exp-Golomb(2) of t0 and of every
//      t_i - t_(i-1) - 1.
//   After the last row only zero padding bits may remain, and no further bytes. The encoding is
//   canonical: the decoder rejects overlong varints and explicit rows that could be deltas, so a
//   mask has exactly one encoding per coding.
//
// Contract of the decoder: it accepts any byte string, never reads or writes out of bounds, and
// returns an Error (one line) for anything that is not exactly the encoding of a valid RunMask
// (bad magic, unknown coding, sizes over the limit, truncated data, runs that overlap, touch,
// leave the row or are empty, trailing bytes). Its memory and time are O(input bytes + height):
// every decoded run costs at least two bits of input. Decoding yields runs directly (no image),
// which is what the hull cuts with.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/run_mask.h"

namespace studio {

enum class MaskCoding : uint8_t {
  kRuns = 1,      // plain row-major runs with varints (the paper's kind of RLE)
  kRowDelta = 2,  // transitions relative to the row above (default, smallest for actor masks)
};

inline constexpr uint8_t kMaskMagic = 0x4D;
inline constexpr int kMaxMaskSide = 32768;

// Appends nothing; replaces `out` (its capacity is reused). Precondition: mask.valid() and both
// sides <= kMaxMaskSide (std::invalid_argument otherwise: a programming error).
void encode_mask(const RunMask& mask, MaskCoding coding, std::vector<uint8_t>& out);
std::vector<uint8_t> encode_mask(const RunMask& mask, MaskCoding coding = MaskCoding::kRowDelta);

// Decodes a mask. To reuse storage frame after frame, move the previous mask in:
//   auto r = decode_mask(bytes, std::move(mask)); if (r) mask = std::move(*r);
// (The API has no Expected<void> overload on purpose: clang 14, which builds the fuzzers, cannot
// compile std::expected<void, Error>.)
Expected<RunMask> decode_mask(std::span<const uint8_t> bytes, RunMask reuse = RunMask(0, 0));

namespace detail {
// The decoder behind decode_mask(): an error line, or "" with the mask in `out` (on error `out`
// holds garbage runs of the right size). For the libFuzzer target, which is built by clang 14
// and so cannot destroy any std::expected<T, studio::Error>.
std::string decode_mask_into(std::span<const uint8_t> bytes, RunMask& out);
}  // namespace detail

}  // namespace studio

#include "sim/frame_stamp.h"

namespace studio::sim {
namespace {

constexpr int kBits = kStampColumns * kStampRows;  // 48

uint8_t check_of(uint64_t number) {
  uint8_t x = 0;
  for (int i = 0; i < 5; ++i) x ^= uint8_t(number >> (8 * i));
  return uint8_t(~x);
}

uint64_t code_of(uint64_t frame) {
  const uint64_t number = frame & ((uint64_t(1) << 40) - 1);
  return (number << 8) | check_of(number);
}

}  // namespace

void stamp_frame(ImageView<Rgb8> image, uint64_t frame, int cell) {
  if (cell < 1 || image.width() < kStampColumns * cell || image.height() < kStampRows * cell)
    return;
  const uint64_t code = code_of(frame);
  for (int b = 0; b < kBits; ++b) {
    const uint8_t v = (code >> (kBits - 1 - b)) & 1 ? 255 : 0;
    const int x0 = (b % kStampColumns) * cell, y0 = (b / kStampColumns) * cell;
    for (int y = y0; y < y0 + cell; ++y)
      for (int x = x0; x < x0 + cell; ++x) image(x, y) = {v, v, v};
  }
}

std::optional<uint64_t> read_frame_stamp(ImageView<const Rgb8> image, int cell) {
  if (cell < 1 || image.width() < kStampColumns * cell || image.height() < kStampRows * cell)
    return std::nullopt;
  const int lo = cell / 4, hi = cell - cell / 4;  // the middle half of a cell
  uint64_t code = 0;
  for (int b = 0; b < kBits; ++b) {
    const int x0 = (b % kStampColumns) * cell, y0 = (b / kStampColumns) * cell;
    int sum = 0, n = 0;
    for (int y = y0 + lo; y < y0 + hi; ++y)
      for (int x = x0 + lo; x < x0 + hi; ++x, ++n) {
        const Rgb8 p = image(x, y);
        sum += p.r + p.g + p.b;
      }
    code = (code << 1) | (sum > 3 * 128 * n ? 1 : 0);
  }
  const uint64_t number = code >> 8;
  if (uint8_t(code & 0xFF) != check_of(number)) return std::nullopt;
  return number;
}

}  // namespace studio::sim

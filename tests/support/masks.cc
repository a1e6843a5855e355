#include "support/masks.h"

#include <cstddef>
#include <stdexcept>

namespace studio::support {

double iou(const Mask& a, const Mask& b) {
  if (a.width() != b.width() || a.height() != b.height()) throw std::invalid_argument("iou: mask sizes differ");
  std::size_t inter = 0, uni = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const bool p = a(x, y) != 0, q = b(x, y) != 0;
      inter += p && q;
      uni += p || q;
    }
  }
  return uni == 0 ? 1.0 : double(inter) / double(uni);
}

double iou(const RunMask& a, const RunMask& b) {
  if (a.width() != b.width() || a.height() != b.height()) throw std::invalid_argument("iou: mask sizes differ");
  std::size_t inter = 0, uni = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const bool p = a.contains(x, y), q = b.contains(x, y);
      inter += p && q;
      uni += p || q;
    }
  }
  return uni == 0 ? 1.0 : double(inter) / double(uni);
}

}  // namespace studio::support

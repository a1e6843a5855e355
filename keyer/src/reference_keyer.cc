#include "keyer/reference_keyer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace studio::keyer {

Mask reference_key(ImageView<const Rgb8> frame, const KeyerOptions& options, const Image<Rgb8>* plate) {
  const int w = frame.width(), h = frame.height();
  if (options.mode == KeyMode::kDifference &&
      (!plate || plate->width() != w || plate->height() != h))
    throw std::invalid_argument("reference_key: difference key needs a plate of the frame's size");
  Mask mask(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgb8 p = frame(x, y);
      float alpha = 0.0f;
      switch (options.mode) {
        case KeyMode::kBlue:
          alpha = chroma_alpha(float(p.b) - float(std::max(p.r, p.g)), options);
          break;
        case KeyMode::kGreen:
          alpha = chroma_alpha(float(p.g) - float(std::max(p.r, p.b)), options);
          break;
        case KeyMode::kDifference: {
          const Rgb8 q = (*plate)(x, y);
          const float d = std::max({std::fabs(float(p.r) - q.r), std::fabs(float(p.g) - q.g),
                                    std::fabs(float(p.b) - q.b)});
          alpha = difference_alpha(d, options);
          break;
        }
      }
      mask(x, y) = alpha >= options.matte_threshold ? 255 : 0;
    }
  return mask;
}

}  // namespace studio::keyer

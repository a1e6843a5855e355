#include "keyer/plate_keyer.h"

#include <utility>

namespace studio::keyer {

PlateKeyer::Result PlateKeyer::frame(ImageView<const Rgb8> image, RunMask& mask) {
  Result r;
  if (const int n = pending_.exchange(-1, std::memory_order_acq_rel); n >= 0) {
    keyer_.clear_plate();
    remaining_ = n;
    told_no_plate_ = false;
    r.cleared = n == 0;
  }
  if (remaining_ > 0) {
    if (auto ok = keyer_.capture_plate(image); !ok) {
      r.step = Step::kRefused;
      r.error = ok.error();
      return r;
    }
    r.step = --remaining_ == 0 ? Step::kPlateCaptured : Step::kPlateFrame;
    return r;
  }
  if (keyer_.options().mode == KeyMode::kDifference && !keyer_.has_plate()) {
    r.step = Step::kNoPlate;
    r.first = !std::exchange(told_no_plate_, true);
    return r;
  }
  if (auto ok = keyer_.key(image, mask); !ok) {
    r.step = Step::kRefused;
    r.error = ok.error();
    return r;
  }
  r.step = Step::kKeyed;
  return r;
}

}  // namespace studio::keyer

#pragma once
// One camera's keyer together with its clean-plate commands (CameraControl KeyerPlate, keyer.h):
// the state machine every process that keys a camera runs (the keyer node, and the capture
// node's in-process key). Pure: no threads of its own, no files (keeping plates across restarts
// is KeptPlates, keyer/config/kept_plates.h).
//
// Contract
// - request(n), from any thread: KeyerPlate n (valid_plate_request(n)): 0 clears the plate, n in
//   1..kMaxPlateFrames averages the camera's next n frames into a new one. The newest request
//   wins; the next frame() takes it: the plate is cleared at once (Step::cleared tells the caller
//   to forget a kept plate when n is 0).
// - frame(image, mask), on the one thread that keys this camera, says what it did with a frame:
//     kPlateFrame     averaged into the plate being captured (no mask);
//     kPlateCaptured  the plate's last frame: the new plate is complete (keep it);
//     kNoPlate        the difference key has no plate yet: the frame is not keyed (`first` on
//                     the first such frame since the plate went missing: say it once);
//     kRefused        the keyer refused the frame (`error`: a frame whose size differs from the
//                     plate's, a plate frame of another size than the plate's first); a plate
//                     capture continues with the next frame;
//     kKeyed          `mask` holds the frame's binary mask.

#include <atomic>

#include "core/error.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "keyer/keyer.h"

namespace studio::keyer {

class PlateKeyer {
 public:
  explicit PlateKeyer(Keyer keyer) : keyer_(std::move(keyer)) {}
  PlateKeyer(const PlateKeyer&) = delete;
  PlateKeyer& operator=(const PlateKeyer&) = delete;

  void request(int frames) { pending_.store(frames, std::memory_order_release); }

  enum class Step { kKeyed, kPlateFrame, kPlateCaptured, kNoPlate, kRefused };
  struct Result {
    Step step = Step::kKeyed;
    bool cleared = false;  // a KeyerPlate 0 was applied with this frame
    bool first = false;    // kNoPlate: the first unkeyed frame since the plate went missing
    Error error;           // kRefused
  };
  Result frame(ImageView<const Rgb8> image, RunMask& mask);

  Keyer& keyer() { return keyer_; }
  const Keyer& keyer() const { return keyer_; }
  bool capturing() const { return remaining_ > 0; }

 private:
  Keyer keyer_;
  std::atomic<int> pending_{-1};  // -1: no request
  int remaining_ = 0;             // plate frames still to average
  bool told_no_plate_ = false;
};

}  // namespace studio::keyer

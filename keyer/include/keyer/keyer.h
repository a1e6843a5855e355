#pragma once
// The keyer: camera frame -> binary actor mask as runs (core/run_mask.h), ready for the mask codec
// (core/mask_codec.h) and the hull, plus optional soft alpha and a spill-suppressed preview image.
//
// key() makes the mask row by row: a SIMD kernel (SSSE3, or AVX2 when the CPU has it, chosen at
// run time; a scalar loop otherwise) turns a row of pixels into a bit per pixel, and the set bits
// become runs directly, so no full-resolution intermediate image is ever written. Edge
// refinement (keyer/edge_refine.h) and clean-up (keyer/cleanup.h) then work on the runs. Before
// them the binary decision is exactly alpha >= matte_threshold of the formulas in
// keyer/keyer_options.h (the reference keyer in keyer/reference_keyer.h computes the same mask
// per pixel in floating point; tests compare them).
//
// Frames are RGB8 or BGR8, including frames demosaiced from a Bayer sensor by the capture stage.
// A Keyer is not thread-safe (it keeps scratch buffers); use one per camera.

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "keyer/cleanup.h"
#include "keyer/keyer_options.h"

namespace studio::keyer {

// The camera control (CameraControl.feature) that captures a clean plate for the difference key,
// honoured by whichever process keys the camera (studio-capture, or studio-keyer --config):
// value 0 clears the plate, N in 1..kMaxPlateFrames averages the camera's next N frames.
inline constexpr std::string_view kPlateControl = "KeyerPlate";
inline constexpr int kMaxPlateFrames = 1000;
inline bool valid_plate_request(double value) {
  return value >= 0 && value <= kMaxPlateFrames && value == double(int(value));
}

class Keyer {
 public:
  static Expected<Keyer> create(const KeyerOptions& options);

  const KeyerOptions& options() const { return options_; }

  // Binary mask (after clean-up) into `mask`, reusing its storage. Errors: difference mode
  // without a clean plate, or a frame whose size differs from the plate's.
  Expected<void> key(ImageView<const Rgb8> frame, RunMask& mask);
  Expected<void> key(ImageView<const Bgr8> frame, RunMask& mask);

  // Soft alpha (0 = backing, 255 = actor) into `alpha`, which must have the frame's size.
  Expected<void> soft_alpha(ImageView<const Rgb8> frame, ImageView<uint8_t> alpha) const;
  Expected<void> soft_alpha(ImageView<const Bgr8> frame, ImageView<uint8_t> alpha) const;

  // Clean plate for the difference key, captured on command: the first call after clear_plate()
  // sets it; further calls average more frames into it (reduces sensor noise). Error if the size
  // differs from frames already in the plate.
  Expected<void> capture_plate(ImageView<const Rgb8> frame);
  Expected<void> capture_plate(ImageView<const Bgr8> frame);
  void clear_plate();
  bool has_plate() const { return plate_frames_ > 0; }
  const Image<Rgb8>& plate() const { return plate_; }  // the averaged plate (RGB); empty if none
  int plate_frames() const { return plate_frames_; }

  // Which row kernel runs on this CPU: "avx2", "ssse3" or "scalar".
  static const char* kernel_name();

 private:
  explicit Keyer(const KeyerOptions& options);
  template <class Px>
  Expected<void> key_impl(ImageView<const Px> frame, RunMask& mask);
  template <class Px>
  Expected<void> alpha_impl(ImageView<const Px> frame, ImageView<uint8_t> alpha) const;
  template <class Px>
  Expected<void> plate_impl(ImageView<const Px> frame);
  template <class Px>
  static bool shows_backing(const void* context, int y, int32_t begin, int32_t end);

  KeyerOptions options_;
  uint8_t chroma_max_excess_ = 0;  // foreground iff max(0, K - max(O1, O2)) <= this
  bool chroma_all_ = false;        // every pixel is foreground (threshold above 255)
  uint8_t diff_min_ = 0;           // foreground iff max|I - P| >= this
  uint8_t alpha_lut_[256] = {};    // alpha of an excess (chroma) or a difference (difference key)
  int backing_excess_ = 256;       // chroma: excess at and above which alpha = 0 (clean backing)
  int backing_diff_ = -1;          // difference: diff at and below which alpha = 0
  const void* frame_ = nullptr;    // the frame key() is working on (for shows_backing)
  // Clean plate: per-channel sums over plate_frames_ frames, and their average in RGB order.
  std::vector<uint32_t> plate_sum_;
  Image<Rgb8> plate_;
  int plate_frames_ = 0;
  // Scratch, reused between frames.
  std::vector<uint64_t> row_bits_;
  std::vector<uint8_t> plate_row_;
  RunMask raw_;
  RunMask refined_;
  EdgeRefineScratch edge_scratch_;
  CleanupScratch cleanup_scratch_;
};

// Spill suppression for the image that goes to the preview (in place):
// K' = K - strength * max(0, K - max(O1, O2)) with K the key channel of `mode` (blue for the
// difference key). strength in [0, 1].
void suppress_spill(ImageView<Rgb8> image, KeyMode mode, float strength);
void suppress_spill(ImageView<Bgr8> image, KeyMode mode, float strength);

}  // namespace studio::keyer

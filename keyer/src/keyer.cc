#include "keyer/keyer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "key_kernels.h"

namespace studio::keyer {
namespace {

// Byte offsets of R, G, B inside a pixel.
template <class Px> struct Layout;
template <> struct Layout<Rgb8> { static constexpr int r = 0, g = 1, b = 2; static constexpr bool bgr = false; };
template <> struct Layout<Bgr8> { static constexpr int r = 2, g = 1, b = 0; static constexpr bool bgr = true; };

// Key channel and the other two, as byte offsets, for a chroma mode (blue for the difference key).
template <class Px>
void key_channels(KeyMode mode, int& k, int& o1, int& o2) {
  using L = Layout<Px>;
  if (mode == KeyMode::kGreen) {
    k = L::g, o1 = L::r, o2 = L::b;
  } else {
    k = L::b, o1 = L::r, o2 = L::g;
  }
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

Keyer::Keyer(const KeyerOptions& options) : options_(options) {
  // Tabulate the formulas of keyer_options.h on the integer inputs the kernels see, so the
  // binary decision is exactly the reference keyer's.
  int max_excess = -1;
  for (int e = 0; e < 256; ++e) {
    const float a = chroma_alpha(float(e), options_);
    if (options_.mode != KeyMode::kDifference) alpha_lut_[e] = uint8_t(std::lround(255.0f * a));
    if (a >= options_.matte_threshold) max_excess = e;
  }
  chroma_all_ = max_excess >= 255;
  for (int e = 255; e >= 0 && chroma_alpha(float(e), options_) == 0.0f; --e) backing_excess_ = e;
  for (int d = 0; d < 256 && difference_alpha(float(d), options_) == 0.0f; ++d) backing_diff_ = d;
  chroma_max_excess_ = uint8_t(max_excess < 0 ? 0 : max_excess);  // validate(): alpha(0) = 1
  int min_diff = 256;
  for (int d = 255; d >= 0; --d) {
    const float a = difference_alpha(float(d), options_);
    if (options_.mode == KeyMode::kDifference) alpha_lut_[d] = uint8_t(std::lround(255.0f * a));
    if (a >= options_.matte_threshold) min_diff = d;
  }
  diff_min_ = uint8_t(min_diff > 255 ? 255 : min_diff);  // validate(): diff_high <= 255
}

Expected<Keyer> Keyer::create(const KeyerOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  return Keyer(options);
}

const char* Keyer::kernel_name() { return detail::best_kernels().name; }

template <class Px>
Expected<void> Keyer::key_impl(ImageView<const Px> frame, RunMask& mask) {
  const int w = frame.width(), h = frame.height();
  const bool difference = options_.mode == KeyMode::kDifference;
  if (difference) {
    if (!has_plate()) return fail("difference key: no clean plate captured");
    if (plate_.width() != w || plate_.height() != h)
      return fail("difference key: frame is " + size_text(w, h) + " but the clean plate is " +
                  size_text(plate_.width(), plate_.height()));
  }
  if (raw_.width() == w && raw_.height() == h) raw_.clear(); else raw_ = RunMask(w, h);
  row_bits_.resize(std::size_t(w + 63) / 64 + 1);
  const detail::Kernels& kern = detail::best_kernels();
  int k, o1, o2;
  key_channels<Px>(options_.mode, k, o1, o2);
  const detail::ChromaParams params = detail::make_chroma_params(k, o1, o2, chroma_max_excess_);
  if (difference) plate_row_.resize(std::size_t(w) * 3);
  for (int y = 0; y < h; ++y) {
    const auto* px = reinterpret_cast<const uint8_t*>(frame.row(y));
    if (difference) {
      // The plate is kept in RGB order; BGR frames compare against a swapped copy of the row.
      const auto* plate = reinterpret_cast<const uint8_t*>(&plate_(0, y));
      if constexpr (Layout<Px>::bgr) {
        for (int x = 0; x < w; ++x) {
          plate_row_[3 * x] = plate[3 * x + 2];
          plate_row_[3 * x + 1] = plate[3 * x + 1];
          plate_row_[3 * x + 2] = plate[3 * x];
        }
        plate = plate_row_.data();
      }
      kern.diff(px, plate, w, diff_min_, row_bits_.data());
    } else if (chroma_all_) {
      if (w > 0) raw_.push_run(y, 0, w);
      continue;
    } else {
      kern.chroma(px, w, params, row_bits_.data());
    }
    detail::bits_to_runs(row_bits_.data(), w, y, raw_);
  }
  raw_.finish();
  const RunMask* keyed = &raw_;
  if (options_.edge_refine) {
    refine_edges(frame, raw_, options_.edge, refined_, edge_scratch_);
    keyed = &refined_;
  }
  if (options_.cleanup.keep_backing_gaps) {
    frame_ = &frame;
    clean_mask(*keyed, options_.cleanup, mask, cleanup_scratch_, &Keyer::shows_backing<Px>, this);
    frame_ = nullptr;
  } else {
    clean_mask(*keyed, options_.cleanup, mask, cleanup_scratch_);
  }
  return {};
}

template <class Px>
bool Keyer::shows_backing(const void* context, int y, int32_t begin, int32_t end) {
  const Keyer& self = *static_cast<const Keyer*>(context);
  const ImageView<const Px>& frame = *static_cast<const ImageView<const Px>*>(self.frame_);
  const auto* px = reinterpret_cast<const uint8_t*>(frame.row(y));
  using L = Layout<Px>;
  if (self.options_.mode == KeyMode::kDifference) {
    const auto* plate = reinterpret_cast<const uint8_t*>(&self.plate_(0, y));
    for (int32_t x = begin; x < end; ++x) {
      const uint8_t* q = px + 3 * x;
      const uint8_t* p = plate + 3 * x;
      const int d =
          std::max({std::abs(q[L::r] - p[0]), std::abs(q[L::g] - p[1]), std::abs(q[L::b] - p[2])});
      if (d <= self.backing_diff_) return true;
    }
    return false;
  }
  int k, o1, o2;
  key_channels<Px>(self.options_.mode, k, o1, o2);
  for (int32_t x = begin; x < end; ++x) {
    const uint8_t* q = px + 3 * x;
    if (int(q[k]) - int(std::max(q[o1], q[o2])) >= self.backing_excess_) return true;
  }
  return false;
}

Expected<void> Keyer::key(ImageView<const Rgb8> frame, RunMask& mask) { return key_impl(frame, mask); }
Expected<void> Keyer::key(ImageView<const Bgr8> frame, RunMask& mask) { return key_impl(frame, mask); }

template <class Px>
Expected<void> Keyer::alpha_impl(ImageView<const Px> frame, ImageView<uint8_t> alpha) const {
  const int w = frame.width(), h = frame.height();
  if (alpha.width() != w || alpha.height() != h)
    return fail("soft alpha: output is " + size_text(alpha.width(), alpha.height()) +
                " but the frame is " + size_text(w, h));
  using L = Layout<Px>;
  if (options_.mode == KeyMode::kDifference) {
    if (!has_plate()) return fail("difference key: no clean plate captured");
    if (plate_.width() != w || plate_.height() != h)
      return fail("difference key: frame is " + size_text(w, h) + " but the clean plate is " +
                  size_text(plate_.width(), plate_.height()));
    for (int y = 0; y < h; ++y) {
      const Px* px = frame.row(y);
      uint8_t* out = alpha.row(y);
      for (int x = 0; x < w; ++x) {
        const uint8_t* q = reinterpret_cast<const uint8_t*>(px + x);
        const Rgb8& p = plate_(x, y);
        const int dr = std::abs(q[L::r] - p.r), dg = std::abs(q[L::g] - p.g), db = std::abs(q[L::b] - p.b);
        out[x] = alpha_lut_[std::max(dr, std::max(dg, db))];
      }
    }
    return {};
  }
  int k, o1, o2;
  key_channels<Px>(options_.mode, k, o1, o2);
  for (int y = 0; y < h; ++y) {
    const auto* px = reinterpret_cast<const uint8_t*>(frame.row(y));
    uint8_t* out = alpha.row(y);
    for (int x = 0; x < w; ++x) {
      const uint8_t* q = px + 3 * x;
      const int excess = int(q[k]) - std::max(q[o1], q[o2]);
      out[x] = excess <= 0 ? alpha_lut_[0] : alpha_lut_[excess];
    }
  }
  return {};
}

Expected<void> Keyer::soft_alpha(ImageView<const Rgb8> frame, ImageView<uint8_t> alpha) const {
  return alpha_impl(frame, alpha);
}
Expected<void> Keyer::soft_alpha(ImageView<const Bgr8> frame, ImageView<uint8_t> alpha) const {
  return alpha_impl(frame, alpha);
}

template <class Px>
Expected<void> Keyer::plate_impl(ImageView<const Px> frame) {
  const int w = frame.width(), h = frame.height();
  if (plate_frames_ > 0 && (plate_.width() != w || plate_.height() != h))
    return fail("clean plate: frame is " + size_text(w, h) + " but the plate is " +
                size_text(plate_.width(), plate_.height()));
  if (plate_frames_ == 0) {
    plate_ = Image<Rgb8>(w, h);
    plate_sum_.assign(std::size_t(w) * h * 3, 0);
  }
  ++plate_frames_;
  using L = Layout<Px>;
  const uint32_t n = uint32_t(plate_frames_);
  for (int y = 0; y < h; ++y) {
    const auto* px = reinterpret_cast<const uint8_t*>(frame.row(y));
    uint32_t* sum = plate_sum_.data() + std::size_t(y) * w * 3;
    for (int x = 0; x < w; ++x) {
      sum[3 * x] += px[3 * x + L::r];
      sum[3 * x + 1] += px[3 * x + L::g];
      sum[3 * x + 2] += px[3 * x + L::b];
      plate_(x, y) = Rgb8{uint8_t((sum[3 * x] + n / 2) / n), uint8_t((sum[3 * x + 1] + n / 2) / n),
                          uint8_t((sum[3 * x + 2] + n / 2) / n)};
    }
  }
  return {};
}

Expected<void> Keyer::capture_plate(ImageView<const Rgb8> frame) { return plate_impl(frame); }
Expected<void> Keyer::capture_plate(ImageView<const Bgr8> frame) { return plate_impl(frame); }

void Keyer::clear_plate() {
  plate_frames_ = 0;
  plate_ = Image<Rgb8>();
  plate_sum_.clear();
}

template <class Px>
static void spill_impl(ImageView<Px> image, KeyMode mode, float strength) {
  int k, o1, o2;
  key_channels<Px>(mode, k, o1, o2);
  const int s = int(std::lround(strength * 256.0f));
  for (int y = 0; y < image.height(); ++y) {
    auto* px = reinterpret_cast<uint8_t*>(image.row(y));
    for (int x = 0; x < image.width(); ++x) {
      uint8_t* q = px + 3 * x;
      const int excess = int(q[k]) - std::max(q[o1], q[o2]);
      if (excess > 0) q[k] = uint8_t(q[k] - ((excess * s + 128) >> 8));
    }
  }
}

void suppress_spill(ImageView<Rgb8> image, KeyMode mode, float strength) { spill_impl(image, mode, strength); }
void suppress_spill(ImageView<Bgr8> image, KeyMode mode, float strength) { spill_impl(image, mode, strength); }

}  // namespace studio::keyer

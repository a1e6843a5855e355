#pragma once
// Image files for the CLI (OpenCV; never in the keyer library).

#include <string>

#include "core/error.h"
#include "core/image.h"

namespace studio::keyer {

// PNG/JPEG/... as 8-bit RGB (grey and 16-bit images are converted). One-line error when the
// file is missing or cannot be decoded.
Expected<Image<Rgb8>> read_rgb(const std::string& path);
Expected<void> write_mask_png(const std::string& path, const Mask& mask);
// RGB as PNG, atomically: written beside `path` and renamed over it, so a crash never leaves a
// torn file where a plate was.
Expected<void> write_rgb_png(const std::string& path, const Image<Rgb8>& image);

}  // namespace studio::keyer

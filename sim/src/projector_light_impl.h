#pragma once
// Private to the simulated studio: the projector light drawn into a camera's cyclorama background
// (sim/projector_light.h (c); called by studio.cc when the background is built).

#include <cstdint>

#include "core/camera.h"
#include "core/image.h"
#include "sim/projector_light.h"

namespace studio::sim::detail {

// Surface codes of CameraCache::surface (studio_impl.h Surface) this file reads and writes.
inline constexpr uint8_t kSurfaceNone = 0;
inline constexpr uint8_t kSurfaceBoard = 3;

// Rescales the background for the ring level and exposure, draws the boards (surface set to
// kSurfaceBoard) and adds the projectors' light as the camera records it.
void light_background(const ProjectorLight& light, const Cyclorama& cyc, const Camera& cam,
                      Image<Rgb8>* background, Image<uint8_t>* surface);

}  // namespace studio::sim::detail

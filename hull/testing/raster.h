#pragma once
// A small scanline triangle rasteriser for tests: the silhouette of a mesh seen by a camera.
// Pixel convention of core/camera.h: pixel (u, v) is covered when its CENTRE (u, v) lies inside
// (or on the border of) a projected triangle. Vertices are projected with Camera::project
// (distortion included; edges between projected vertices are straight). Triangles with a vertex
// behind the camera are skipped. Not part of the library.

#include "core/camera.h"
#include "core/image.h"
#include "hull/segment_mesh.h"

namespace studio::hull::testing {

// 255 where the mesh covers the pixel centre, 0 elsewhere; camera.width x camera.height.
Mask rasterise(const Mesh& mesh, const Camera& camera);

}  // namespace studio::hull::testing

#pragma once
// Draws the preview's overlays (preview/overlays.h: head marker, camera and projector frusta,
// projector screens with what each projector shows) into the bound framebuffer after the scene
// and the actor, lines and screens depth-tested against them (OpenGL 3.3 core; GL names are plain
// unsigned ints).
//
// Lines are drawn 2 px wide where the context allows (else 1 px); spheres as shaded UV spheres
// (normal-facing light, so the marker reads as a ball) over everything, without the depth test
// (the head marker lies inside the actor's head mesh); a screen as two triangles whose
// fragments look up the projector's thumbnail at the projector pixel of their world point
// (projective texturing: u = (x + 0.5) / width, v = (y + 0.5) / height of the pixel K [R | t] x,
// pixel centres at integers, the thumbnail's top row first), `screen_unlit` outside the
// projector's image or without a thumbnail yet.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/error.h"
#include "preview/overlays.h"

namespace studio::preview {

class OverlayRenderer {
 public:
  static Expected<OverlayRenderer> create();
  OverlayRenderer(OverlayRenderer&&) noexcept;
  OverlayRenderer& operator=(OverlayRenderer&&) noexcept;
  ~OverlayRenderer();

  // The latest thumbnail of a projector (RGB8, width * height * 3 bytes, top row first).
  Expected<void> set_thumbnail(const std::string& projector_id, int width, int height,
                               const uint8_t* rgb);
  struct Texture {
    unsigned name = 0;
    int width = 0, height = 0;
  };
  // The projector's thumbnail texture (for the Projectors panel), if one was set.
  std::optional<Texture> thumbnail(const std::string& projector_id) const;

  // Draws the geometry from clip_from_world into a width x height viewport of the bound
  // framebuffer. Leaves depth test on, blending off.
  void draw(const OverlayGeometry& geometry, const Eigen::Matrix4d& clip_from_world, int width,
            int height);

 private:
  struct Impl;
  explicit OverlayRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::preview

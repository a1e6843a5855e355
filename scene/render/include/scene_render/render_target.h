#pragma once
// An offscreen target: a framebuffer object with an RGBA8 colour texture and a 24-bit depth
// buffer. Draw into it after bind(); read it back, or use colour_texture() in another pass
// (render to texture: the projector warps the rendered view onto its screen).
// Needs a current OpenGL 3.3 context; GL names are plain unsigned ints (GLuint).

#include <cstdint>
#include <vector>

#include "core/error.h"

namespace studio::scene_render {

class RenderTarget {
 public:
  static Expected<RenderTarget> create(int width, int height);
  RenderTarget(RenderTarget&&) noexcept;
  RenderTarget& operator=(RenderTarget&&) noexcept;
  ~RenderTarget();

  // Binds the framebuffer and sets the viewport to the whole target.
  void bind() const;
  // Binds the default framebuffer (a window's) with a viewport of width x height.
  static void bind_default(int width, int height);

  // RGBA8 pixels, top row first (image order), into `out` (resized only when its size differs:
  // reading every frame into the same vector does not allocate).
  void read_rgba(std::vector<std::uint8_t>& out) const;

  int width() const { return width_; }
  int height() const { return height_; }
  unsigned colour_texture() const { return colour_; }
  unsigned framebuffer() const { return fbo_; }

 private:
  RenderTarget() = default;
  void release();
  int width_ = 0, height_ = 0;
  unsigned fbo_ = 0, colour_ = 0, depth_ = 0;
  mutable std::vector<std::uint8_t> row_;
};

}  // namespace studio::scene_render

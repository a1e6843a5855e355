#pragma once
// A headless OpenGL 3.3 core context: EGL on Mesa's surfaceless platform
// (EGL_MESA_platform_surfaceless + EGL_KHR_surfaceless_context), no display, no window, works
// as root with no X server. With no GPU Mesa renders with llvmpipe; LIBGL_ALWAYS_SOFTWARE=1
// forces it when a GPU is present. Draw into a RenderTarget (there is no default framebuffer).
// The context is current on the creating thread after create().

#include <memory>
#include <string>

#include "core/error.h"

namespace studio::scene_render {

class HeadlessContext {
 public:
  // Errors name the EGL step that failed ("EGL: no surfaceless platform (...)").
  static Expected<HeadlessContext> create();
  HeadlessContext(HeadlessContext&&) noexcept;
  HeadlessContext& operator=(HeadlessContext&&) noexcept;
  ~HeadlessContext();

  Expected<void> make_current() const;
  std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  struct Impl;
  explicit HeadlessContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::scene_render

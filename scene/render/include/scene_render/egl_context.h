#pragma once
// A headless OpenGL 3.3 core context: EGL on Mesa's surfaceless platform
// (EGL_MESA_platform_surfaceless + EGL_KHR_surfaceless_context), no display, no window, works
// as root with no X server. With no GPU Mesa renders with llvmpipe; LIBGL_ALWAYS_SOFTWARE=1
// forces it when a GPU is present. Draw into a RenderTarget (there is no default framebuffer).
// The context is current on the creating thread after create().
//
// Screens: llvmpipe rasterises every context of one EGL display on one set of threads, in the
// order the contexts flush (one queue per screen). `EglScreen::own` puts the context on a
// display of its own (EGL_EXT_platform_device, Mesa's software device): its own llvmpipe screen,
// whose rasteriser threads are created by this call on the calling thread (they inherit its
// scheduling priority) and never queue behind another display's work. It shares no objects
// with the other contexts; images go between them through memory. Displays are counted in the
// process: destroying a context terminates its display only when it was the display's last.

#include <memory>
#include <string>

#include "core/error.h"

namespace studio::scene_render {

enum class EglScreen { shared, own };

class HeadlessContext {
 public:
  // Errors name the EGL step that failed ("EGL: no surfaceless platform (...)").
  static Expected<HeadlessContext> create(EglScreen screen = EglScreen::shared);
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

#pragma once
// The projector's picture on a real projector (issue 15 item 3: "headless EGL, or a GLFW
// full-screen window on a named monitor, same code"): a full-screen GLFW window on the monitor
// the projector is plugged into, with an OpenGL 3.3 core context that the same FrameRenderer
// renders in. Each frame is rendered into the renderer's own target exactly as headless (so the
// blackout read-back and the thumbnail are the same), then blitted to the window's default
// framebuffer (scaled if the monitor's mode differs from the projector's size; a real setup
// gives the projector its native mode) and swapped.
//
// The window uses the monitor's current video mode (no mode switch: "windowed full screen"),
// no decorations, no cursor, swap interval 0 (the projector's frames are driven by meshes, not
// by the display's refresh). The context is current on the creating thread; create, show and
// destroy on that thread (the render thread).

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::projector {

class WindowOutput {
 public:
  // monitor: the name GLFW reports for it (xrandr's output name on X11, e.g. "HDMI-1"), or
  // "primary". Errors: no display (GLFW cannot initialise), a monitor not found (the message
  // lists the connected ones), no OpenGL 3.3 core context.
  static Expected<WindowOutput> create(const std::string& monitor, const std::string& title);
  WindowOutput(WindowOutput&&) noexcept;
  WindowOutput& operator=(WindowOutput&&) noexcept;
  ~WindowOutput();

  // The names of the connected monitors (GLFW initialised by the caller or by create()).
  static std::vector<std::string> monitors();
  std::string renderer() const;  // GL_RENDERER
  std::string monitor() const;   // the monitor's name
  int width() const;             // the window's framebuffer, pixels
  int height() const;
  // Shows the colour of `framebuffer` (width x height, the renderer's target) in the window:
  // blit to the default framebuffer, swap. Polls the window's events.
  void show(unsigned framebuffer, int width, int height);

 private:
  struct Impl;
  explicit WindowOutput(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace studio::projector

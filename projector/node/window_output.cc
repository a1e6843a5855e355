#include "window_output.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
// GLFW after the GL headers (it must not include its own).
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace studio::projector {

struct WindowOutput::Impl {
  GLFWwindow* window = nullptr;
  std::string monitor;
  ~Impl() {
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }
};

WindowOutput::WindowOutput(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WindowOutput::WindowOutput(WindowOutput&&) noexcept = default;
WindowOutput& WindowOutput::operator=(WindowOutput&&) noexcept = default;
WindowOutput::~WindowOutput() = default;

std::vector<std::string> WindowOutput::monitors() {
  std::vector<std::string> out;
  int n = 0;
  GLFWmonitor** all = glfwGetMonitors(&n);
  for (int i = 0; i < n; ++i) {
    const char* name = glfwGetMonitorName(all[i]);
    out.emplace_back(name ? name : "");
  }
  return out;
}

Expected<WindowOutput> WindowOutput::create(const std::string& monitor, const std::string& title) {
  if (!glfwInit()) return fail("output: window: no display (GLFW could not initialise; DISPLAY?)");
  auto impl = std::make_unique<Impl>();  // terminates GLFW on every error path
  GLFWmonitor* chosen = nullptr;
  if (monitor == "primary") {
    chosen = glfwGetPrimaryMonitor();
  } else {
    int n = 0;
    GLFWmonitor** all = glfwGetMonitors(&n);
    for (int i = 0; i < n && !chosen; ++i)
      if (const char* name = glfwGetMonitorName(all[i]); name && monitor == name) chosen = all[i];
  }
  if (!chosen) {
    std::string names;
    for (const auto& m : monitors()) names += (names.empty() ? "" : ", ") + m;
    return fail("output: monitor '" + monitor + "' not found (connected: " +
                (names.empty() ? std::string("none") : names) + ", or primary)");
  }
  const char* name = glfwGetMonitorName(chosen);
  impl->monitor = name ? name : "";
  const GLFWvidmode* mode = glfwGetVideoMode(chosen);
  if (!mode) return fail("output: monitor '" + impl->monitor + "' has no video mode");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RED_BITS, mode->redBits);
  glfwWindowHint(GLFW_GREEN_BITS, mode->greenBits);
  glfwWindowHint(GLFW_BLUE_BITS, mode->blueBits);
  glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
  glfwWindowHint(GLFW_AUTO_ICONIFY, GLFW_FALSE);  // stays up when another window takes focus
  impl->window = glfwCreateWindow(mode->width, mode->height, title.c_str(), chosen, nullptr);
  if (!impl->window) return fail("output: window: no OpenGL 3.3 core context on this display");
  glfwMakeContextCurrent(impl->window);
  glfwSwapInterval(0);
  glfwSetInputMode(impl->window, GLFW_CURSOR, GLFW_CURSOR_HIDDEN);
  return WindowOutput(std::move(impl));
}

std::string WindowOutput::renderer() const {
  const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return r ? r : "";
}

std::string WindowOutput::monitor() const { return impl_->monitor; }

int WindowOutput::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return w;
}

int WindowOutput::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return h;
}

void WindowOutput::show(unsigned framebuffer, int width, int height) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDrawBuffer(GL_BACK);
  // Both are bottom-up GL framebuffers: rows map as they are.
  glBlitFramebuffer(0, 0, width, height, 0, 0, w, h, GL_COLOR_BUFFER_BIT,
                    w == width && h == height ? GL_NEAREST : GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glfwSwapBuffers(impl_->window);
  glfwPollEvents();
}

}  // namespace studio::projector

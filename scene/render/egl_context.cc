#include "scene_render/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <map>
#include <mutex>

#include "gl.h"

namespace studio::scene_render {

namespace {

// Contexts per initialised display in this process: eglInitialize of an initialised display
// does nothing and eglTerminate releases it whatever else still uses it, so the last context
// of a display terminates it.
std::mutex g_displays_mutex;
std::map<EGLDisplay, int> g_displays;

bool initialise(EGLDisplay display) {
  std::lock_guard lock(g_displays_mutex);
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return false;
  ++g_displays[display];
  return true;
}

void release(EGLDisplay display) {
  std::lock_guard lock(g_displays_mutex);
  auto it = g_displays.find(display);
  if (it == g_displays.end() || --it->second > 0) return;
  g_displays.erase(it);
  eglTerminate(display);
}

}  // namespace

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;  // initialised (counted) when set
  EGLContext context = EGL_NO_CONTEXT;
  ~Impl() {
    if (display != EGL_NO_DISPLAY) {
      if (eglGetCurrentContext() == context)
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
      release(display);
    }
  }
};

namespace {

std::string egl_error(const char* step) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "EGL: %s failed (error 0x%04x)", step, eglGetError());
  return buf;
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

}  // namespace

HeadlessContext::HeadlessContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HeadlessContext::HeadlessContext(HeadlessContext&&) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&&) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

Expected<HeadlessContext> HeadlessContext::create(EglScreen screen) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) return fail("EGL: eglGetPlatformDisplayEXT missing");
  EGLDisplay display = EGL_NO_DISPLAY;
  if (screen == EglScreen::own) {
    // Mesa's software device: a display (and llvmpipe screen) apart from the surfaceless one.
    if (!has_extension(client, "EGL_EXT_platform_device") ||
        !has_extension(client, "EGL_EXT_device_enumeration"))
      return fail("EGL: no device platform (EGL_EXT_platform_device missing)");
    auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
        eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (!query_devices || !device_string) return fail("EGL: eglQueryDevicesEXT missing");
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (!query_devices(16, devices, &n)) return fail(egl_error("eglQueryDevicesEXT"));
    for (EGLint i = 0; i < n && display == EGL_NO_DISPLAY; ++i)
      if (has_extension(device_string(devices[i], EGL_EXTENSIONS), "EGL_MESA_device_software"))
        display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display == EGL_NO_DISPLAY)
      return fail("EGL: no software device (EGL_MESA_device_software) for a screen of its own");
  } else {
    if (!has_extension(client, "EGL_MESA_platform_surfaceless"))
      return fail(
          "EGL: no surfaceless platform (EGL_MESA_platform_surfaceless missing; is Mesa's "
          "libegl-mesa0 installed?)");
    display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display == EGL_NO_DISPLAY) return fail(egl_error("eglGetPlatformDisplayEXT(surfaceless)"));
  }
  if (!initialise(display)) return fail(egl_error("eglInitialize"));
  auto impl = std::make_unique<Impl>();
  impl->display = display;
  if (!has_extension(eglQueryString(impl->display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
    return fail("EGL: EGL_KHR_surfaceless_context missing");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail(egl_error("eglBindAPI(OpenGL)"));
  const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!eglChooseConfig(impl->display, config_attribs, &config, 1, &count) || count < 1)
    config = nullptr;  // EGL_KHR_no_config_context: Mesa accepts a context without a config
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    3,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    3,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
  impl->context = eglCreateContext(impl->display, config, EGL_NO_CONTEXT, context_attribs);
  if (impl->context == EGL_NO_CONTEXT) return fail(egl_error("eglCreateContext(OpenGL 3.3 core)"));
  HeadlessContext ctx(std::move(impl));
  if (auto ok = ctx.make_current(); !ok) return std::unexpected(ok.error());
  return ctx;
}

Expected<void> HeadlessContext::make_current() const {
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context))
    return fail(egl_error("eglMakeCurrent(surfaceless)"));
  return {};
}

std::string HeadlessContext::renderer() const {
  const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return s ? s : "";
}

}  // namespace studio::scene_render

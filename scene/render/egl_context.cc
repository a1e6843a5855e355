#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>

#include "gl.h"
#include "scene_render/egl_context.h"

namespace studio::scene_render {

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  ~Impl() {
    if (display != EGL_NO_DISPLAY) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
      eglTerminate(display);
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

Expected<HeadlessContext> HeadlessContext::create() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(client, "EGL_MESA_platform_surfaceless"))
    return fail("EGL: no surfaceless platform (EGL_MESA_platform_surfaceless missing; is Mesa's libegl-mesa0 installed?)");
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) return fail("EGL: eglGetPlatformDisplayEXT missing");
  auto impl = std::make_unique<Impl>();
  impl->display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (impl->display == EGL_NO_DISPLAY) return fail(egl_error("eglGetPlatformDisplayEXT(surfaceless)"));
  EGLint major = 0, minor = 0;
  if (!eglInitialize(impl->display, &major, &minor)) {
    impl->display = EGL_NO_DISPLAY;
    return fail(egl_error("eglInitialize"));
  }
  if (!has_extension(eglQueryString(impl->display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
    return fail("EGL: EGL_KHR_surfaceless_context missing");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail(egl_error("eglBindAPI(OpenGL)"));
  const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!eglChooseConfig(impl->display, config_attribs, &config, 1, &count) || count < 1)
    config = nullptr;  // EGL_KHR_no_config_context: Mesa accepts a context without a config
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3,
                                    EGL_CONTEXT_MINOR_VERSION, 3,
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

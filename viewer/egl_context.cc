#include "viewer/egl_context.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "core/error.h"

namespace parallax {
namespace {

[[noreturn]] void ThrowEglError(const std::string& step) {
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04x", static_cast<unsigned>(eglGetError()));
  throw ToolError("EGL: " + step + " failed (error " + code +
                  "); headless rendering needs Mesa's EGL (Debian packages libegl-mesa0 "
                  "libgl1-mesa-dri)");
}

}  // namespace

struct HeadlessGlContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

HeadlessGlContext::HeadlessGlContext(bool force_software) : impl_(std::make_unique<Impl>()) {
  if (force_software) ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  // Plain eglGetDisplay would pick Mesa's X11 platform and fail without a display.
  const auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) ThrowEglError("eglGetPlatformDisplayEXT lookup");
  impl_->display =
      get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (impl_->display == EGL_NO_DISPLAY) ThrowEglError("surfaceless display");
  EGLint major = 0, minor = 0;
  if (!eglInitialize(impl_->display, &major, &minor)) ThrowEglError("eglInitialize");
  if (!eglBindAPI(EGL_OPENGL_API)) ThrowEglError("eglBindAPI(OpenGL)");
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  // No config and no surface: everything is drawn into framebuffer objects.
  impl_->context =
      eglCreateContext(impl_->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (impl_->context == EGL_NO_CONTEXT) ThrowEglError("OpenGL 3.3 core context");
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context)) {
    ThrowEglError("eglMakeCurrent");
  }
}

HeadlessGlContext::~HeadlessGlContext() {
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (impl_->context != EGL_NO_CONTEXT) eglDestroyContext(impl_->display, impl_->context);
  // The display is not terminated: Mesa shares it per process, and other contexts may use it.
}

}  // namespace parallax

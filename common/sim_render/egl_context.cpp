#include "common/sim_render/egl_context.h"

#include <mutex>

#include <EGL/egl.h>
#include <EGL/eglext.h>

namespace bookgrasp::sim_render {
namespace {

std::string egl_error_text() {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "0x%04X", static_cast<unsigned>(eglGetError()));
  return buf;
}

/// The process-wide surfaceless display, initialised once.
EGLDisplay shared_display() {
  static std::once_flag once;
  static EGLDisplay display = EGL_NO_DISPLAY;
  static std::string failure;
  std::call_once(once, [] {
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) {
      failure = "eglGetPlatformDisplayEXT is missing (install libegl-mesa0 and libgl1-mesa-dri)";
      return;
    }
    EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d == EGL_NO_DISPLAY) {
      failure = "no EGL surfaceless display (EGL error " + egl_error_text() +
                "; install libegl-mesa0 and libgl1-mesa-dri)";
      return;
    }
    EGLint major = 0, minor = 0;
    if (eglInitialize(d, &major, &minor) != EGL_TRUE) {
      failure = "eglInitialize failed on the surfaceless display (EGL error " + egl_error_text() + ")";
      return;
    }
    display = d;
  });
  if (display == EGL_NO_DISPLAY) throw RenderError("offscreen rendering unavailable: " + failure);
  return display;
}

}  // namespace

EglContext::EglContext() {
  EGLDisplay display = shared_display();
  const EGLint config_attribs[] = {EGL_RED_SIZE,   8, EGL_GREEN_SIZE,      8, EGL_BLUE_SIZE,       8,
                                   EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE,      24, EGL_STENCIL_SIZE,   8,
                                   EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (eglChooseConfig(display, config_attribs, &config, 1, &num_configs) != EGL_TRUE || num_configs < 1) {
    throw RenderError("no EGL config with RGBA8, depth 24, stencil 8 and desktop OpenGL (EGL error " +
                      egl_error_text() + ")");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    throw RenderError("eglBindAPI(EGL_OPENGL_API) failed (EGL error " + egl_error_text() + ")");
  }
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, nullptr);
  if (context == EGL_NO_CONTEXT) {
    throw RenderError("eglCreateContext failed (EGL error " + egl_error_text() + ")");
  }
  display_ = display;
  context_ = context;
  make_current();
}

EglContext::~EglContext() {
  if (context_) {
    if (eglGetCurrentContext() == static_cast<EGLContext>(context_)) {
      eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(static_cast<EGLDisplay>(display_), static_cast<EGLContext>(context_));
  }
}

void EglContext::make_current() {
  if (eglGetCurrentContext() == static_cast<EGLContext>(context_)) return;
  if (eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE,
                     static_cast<EGLContext>(context_)) != EGL_TRUE) {
    throw RenderError("eglMakeCurrent failed (EGL error " + egl_error_text() + ")");
  }
}

}  // namespace bookgrasp::sim_render

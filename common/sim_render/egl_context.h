#pragma once
/// @file
/// A headless OpenGL context: EGL on Mesa's surfaceless platform (no display,
/// no GPU needed; llvmpipe renders on the CPU). MuJoCo renders into its own
/// offscreen framebuffer, so the context needs no surface.

#include <stdexcept>
#include <string>

namespace bookgrasp::sim_render {

/// Thrown when no OpenGL context can be made; the text says which EGL step
/// failed and what to install or set.
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One OpenGL (compatibility profile) context on the EGL surfaceless display.
/// The display is shared by the whole process and never terminated (several
/// contexts may live at once); each context is destroyed with its object.
/// A context is current on one thread at a time: call make_current() on the
/// thread that renders before any GL or mjr_* call.
class EglContext {
 public:
  /// Creates the context and makes it current on the calling thread.
  /// Throws RenderError if EGL or the surfaceless platform is unavailable.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes this context current on the calling thread (cheap if it already is).
  void make_current();

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
};

}  // namespace bookgrasp::sim_render

#pragma once
// A headless OpenGL context: EGL on Mesa's surfaceless platform, no window and no X server.
// Rendering goes into framebuffer objects (docs/design.md, "Headless rendering").
#include <memory>

namespace parallax {

class HeadlessGlContext {
 public:
  // Creates an OpenGL 3.3 core context and makes it current on the calling thread.
  // `force_software` sets LIBGL_ALWAYS_SOFTWARE=1 first, so Mesa picks llvmpipe even on a
  // machine with a GPU (bit-identical results everywhere). Throws ToolError naming the EGL
  // step that failed and the packages to install.
  explicit HeadlessGlContext(bool force_software = true);
  ~HeadlessGlContext();
  HeadlessGlContext(const HeadlessGlContext&) = delete;
  HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace parallax

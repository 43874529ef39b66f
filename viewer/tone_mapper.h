#pragma once
// The tone mapper and the exposure meter: a frame drawn in linear light into the float frame
// (FrameSettings::tone_map other than kClamp, or auto_exposure) is exposed and mapped into the
// 8-bit sRGB frame by one screen-covering triangle. With auto exposure, a shrunk copy of the
// float frame is read back for its log-average luminance, and the eye adapts towards it over
// the settings' time constant. With FrameSettings::glare, the light over the display's white is
// spread into a halo first (viewer/glare.h). Needs a current GL context.
#include <optional>

#include "viewer/frame.h"
#include "viewer/gl.h"
#include "viewer/glare.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class ToneMapper {
 public:
  // `clock` times the eye's adaptation. Throws std::runtime_error if the program does not
  // compile.
  explicit ToneMapper(FrameClock clock);

  // Exposes and maps eye.hdr into eye.color, then leaves the frame's draw buffers as they were:
  // the color, and the auxiliary target when `with_aux`.
  void Map(const FrameSettings& settings, const gpu::EyeTarget& eye, bool with_aux);

  // The framebuffer whose first attachment holds the last frame mapped in linear light, before
  // exposure (after the glare where there was one): eye.hdr's or the glare's.
  GLuint LinearFramebuffer() const { return linear_framebuffer_; }

 private:
  // The linear scale of the frame: 2^exposure_stops, with auto exposure times mid grey over the
  // adapted luminance.
  double Exposure(const FrameSettings& settings, const gpu::EyeTarget& eye);
  // The float frame's log-average luminance (of a 64x36 shrunk copy).
  double LogAverageLuminance(const gpu::EyeTarget& eye);

  GlProgram program_;
  std::optional<Glare> glare_;  // Made at the first frame that asks for it.
  GLuint linear_framebuffer_ = 0;
  GlVertexArray empty_vao_;  // The triangle has no vertex buffer.
  gpu::FloatTarget meter_;   // The float frame shrunk, to read its brightness back.
  FrameClock clock_;
  std::optional<double> adapted_luminance_;  // What the eye is adapted to (auto exposure).
  double last_adaptation_ = 0;               // When, on clock_.
};

}  // namespace parallax

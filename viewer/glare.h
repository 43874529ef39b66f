#pragma once
// Glare: the light over the display's white spread into a halo before tone mapping, as an eye
// or a lens scatters it (the seed's HDR rendering: with a float frame "glare can be shown").
// What each channel of a pixel holds over the white is taken out (the pixel then shows white
// where every channel was over it, as a clipped one would) and added back blurred: a pyramid
// of 2x2 averages from 2 to 64 pixels, each level upsampled bilinearly level by level, the six
// averaged. Every level keeps the light it was given, so the frame keeps its light, less what
// spreads past its border. Needs a current GL context.
#include <array>

#include "viewer/gl.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class Glare {
 public:
  static constexpr int kLevels = 6;

  // Throws std::runtime_error if a program does not compile.
  Glare();

  // eye.hdr with what exceeds `white` (an exposed value: linear light times `exposure`) spread
  // into its halo, into Result() (linear light, the eye's size). Leaves the viewport at the
  // eye's size and the depth and stencil tests off.
  void Apply(const gpu::EyeTarget& eye, float exposure, float white);
  const gpu::FloatTarget& Result() const { return result_; }

 private:
  void Resize(int width, int height);

  GlProgram first_level_, upsample_, composite_;
  GlVertexArray empty_vao_;  // The screen triangle has no vertex buffer.
  std::array<gpu::FloatTarget, kLevels> levels_;
  gpu::FloatTarget result_;
  int width_ = 0, height_ = 0;
  int extent_width_ = 0, extent_height_ = 0;  // The frame padded to a multiple of 2^kLevels.
};

}  // namespace parallax

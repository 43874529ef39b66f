#pragma once
// Depth alone, through one program: the shadow map, the projectors' depth maps and the eye's
// depth pre-pass. Needs a current GL context.
#include <Eigen/Core>

#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class DepthPass {
 public:
  // Throws std::runtime_error if the program does not compile.
  DepthPass();

  // Clears `target` and renders the frame's casters into it as `clip_from_world` sees them,
  // each depth pushed back by `slope_bias` times its slope across a texel (plus 4 units).
  void RenderMap(gpu::DepthTarget& target, const Eigen::Matrix4f& clip_from_world, const FrameContext& frame,
                 float slope_bias) const;

  // The frame's mesh into the depth of the bound framebuffer, as the eye sees it (the eye's
  // pre-pass; the caller masks color).
  void DrawEyeDepth(const FrameContext& frame) const;

 private:
  GlProgram program_;
};

}  // namespace parallax

#include "viewer/depth_pass.h"

#include "viewer/shaders.h"

namespace parallax {

DepthPass::DepthPass() : program_("depth", shaders::kDepthVertex, shaders::kDepthFragment) {}

void DepthPass::RenderMap(gpu::DepthTarget& target, const Eigen::Matrix4f& clip_from_world,
                          const FrameContext& frame, float slope_bias) const {
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.Get());
  glViewport(0, 0, target.width, target.height);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glClearDepth(1.0);
  glClear(GL_DEPTH_BUFFER_BIT);
  // Slope-scaled bias against acne: each depth is pushed back by its slope across a texel.
  // No face culling: reconstructed meshes have no consistent winding.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(slope_bias, 4.0f);
  program_.Use();
  program_.Set("u_clip_from_world", clip_from_world);
  frame.DrawCasters(program_, /*depth_only=*/true);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

void DepthPass::DrawEyeDepth(const FrameContext& frame) const {
  program_.Use();
  program_.Set("u_clip_from_world", frame.clip_from_world);
  frame.DrawMeshDepth();
}

}  // namespace parallax

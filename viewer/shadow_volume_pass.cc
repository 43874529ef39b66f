#include "viewer/shadow_volume_pass.h"

#include "viewer/shaders.h"
#include "viewer/shadow_volume.h"

namespace parallax {

ShadowVolumePass::ShadowVolumePass() : program_("shadow volume", shaders::kVolumeVertex, shaders::kDepthFragment) {}

void ShadowVolumePass::Update(const FrameContext& frame) {
  const Key key{frame.light, &frame.cpu_mesh};
  if (key_ == key) return;
  // Casters move away from the light by a thousandth of the scene, so a lit face is not inside
  // its own volume (the volumes' shadow acne).
  const float offset = 1e-3f * frame.scene.FocusRadius();
  volume_.Replace(BuildShadowVolume(frame.cpu_mesh, key.light, offset).vertices);
  key_ = key;
}

// Back faces behind the surface count up, front faces down: the count is the number of casters
// between the surface and the light whether or not the eye is inside a volume, since it is
// taken behind the surface, where the volumes are closed (caps at infinity, depth unclipped).
void ShadowVolumePass::Draw(const FrameContext& frame, const std::function<void()>& redraw_unlit) {
  Update(frame);
  glEnable(GL_STENCIL_TEST);
  glStencilMask(0xff);
  glStencilFunc(GL_ALWAYS, 0, 0xff);
  glStencilOpSeparate(GL_BACK, GL_KEEP, GL_INCR_WRAP, GL_KEEP);
  glStencilOpSeparate(GL_FRONT, GL_KEEP, GL_DECR_WRAP, GL_KEEP);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glEnable(GL_DEPTH_CLAMP);  // Nothing of the volume is clipped by the near or far plane.
  program_.Use();
  program_.Set("u_clip_from_world", frame.clip_from_world);
  glBindVertexArray(volume_.vao.Get());
  glDrawArrays(GL_TRIANGLES, 0, volume_.count);
  glDisable(GL_DEPTH_CLAMP);

  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_NOTEQUAL, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glDepthFunc(frame.DepthLessOrEqual());  // Same geometry, same depth: passes.
  redraw_unlit();
  glDepthMask(GL_TRUE);
  glDepthFunc(frame.DepthLess());
  glDisable(GL_STENCIL_TEST);
}

size_t ShadowVolumePass::Bytes() const { return static_cast<size_t>(volume_.count) * sizeof(Eigen::Vector4f); }

}  // namespace parallax

#include "viewer/planar_shadow_pass.h"

#include "viewer/shaders.h"
#include "viewer/view_math.h"

namespace parallax {

PlanarShadowPass::PlanarShadowPass()
    : program_("planar shadow", shaders::kPlanarVertex, shaders::kPlanarFragment) {}

// Each pixel is marked once however many casters overlap it: no double darkening. Triangles
// within the ground band are the ground itself and cast nothing.
void PlanarShadowPass::Draw(const FrameContext& frame, const std::function<void()>& redraw_unlit) {
  const GroundPlane& ground = *frame.scene.ground;
  const Eigen::Vector4f plane =
      Eigen::Vector4d(ground.normal.x(), ground.normal.y(), ground.normal.z(), ground.offset).cast<float>();
  const float tolerance = frame.ground_band;
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glDisable(GL_DEPTH_TEST);  // The redraw below tests depth against the real ground.
  program_.Use();
  program_.Set("u_clip_from_world", frame.clip_from_world);
  program_.Set("u_planar_shadow", PlanarShadowMatrix(ground, frame.light));
  program_.Set("u_ground", plane);
  program_.Set("u_ground_tolerance", tolerance);
  program_.Set("u_points", frame.HasMesh() ? 0 : 1);
  frame.DrawCasters(program_, /*depth_only=*/false);

  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_EQUAL, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(frame.DepthLessOrEqual());  // Same geometry, same depth: passes.
  ground_ = plane;
  ground_tolerance_ = tolerance;
  redraw_unlit();
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
}

}  // namespace parallax

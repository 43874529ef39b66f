#include "viewer/frame_context.h"

namespace parallax {

Eigen::Vector4d LightVector(const LightSettings& light) {
  if (light.type == LightKind::kPoint) return {light.position.x(), light.position.y(), light.position.z(), 1};
  const Eigen::Vector3d towards = -light.direction.normalized();
  return {towards.x(), towards.y(), towards.z(), 0};
}

Eigen::Vector2f FrameContext::NdcToDepth() const {
  return range == DepthRange::kZeroToOne ? Eigen::Vector2f(1, 0) : Eigen::Vector2f(0.5f, 0.5f);
}

void FrameContext::DrawMeshDepth() const {
  glBindVertexArray(mesh.positions.vao.Get());
  glDrawElements(GL_TRIANGLES, mesh.positions.count, GL_UNSIGNED_INT, nullptr);
}

void FrameContext::DrawCasters(const GlProgram& program, bool depth_only) const {
  if (HasMesh() && depth_only) {
    DrawMeshDepth();
  } else if (HasMesh()) {
    glBindVertexArray(mesh.casters.vao.Get());
    glDrawArrays(GL_TRIANGLES, 0, mesh.casters.count);
  } else if (points.count > 0) {
    program.Set("u_point_size", settings.point_size_px);
    glBindVertexArray(points.vao.Get());
    glDrawArrays(GL_POINTS, 0, points.count);
  }
}

}  // namespace parallax

#pragma once
// What the passes of one frame share: SceneRenderer::Draw builds it, every pass reads it. The
// scene at the frame's level of detail on the GPU, the view, the settings, the light as the
// shaders take it and the depth conventions in force. Needs a current GL context.
#include <vector>

#include <Eigen/Core>

#include "geometry/obj.h"
#include "viewer/frame.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"
#include "viewer/view_math.h"
#include "viewer/viewer_scene.h"

namespace parallax {

// How the surface program treats shadows in a pass (its SHADOW_MODE): none, the shadow map
// (hardware comparison or PCF), or the second pass of planar shadows and shadow volumes, which
// redraws unlit where the stencil marks a shadow.
enum class SurfaceShadow { kNone = 0, kPlanarRedraw = 1, kMap = 2, kPcf = 3, kVolumeRedraw = 4 };

// The light as the shaders take it: (direction towards the light, 0) for a directional light,
// (position, 1) for a point light.
Eigen::Vector4d LightVector(const LightSettings& light);

struct FrameContext {
  const ViewerScene& scene;
  const ViewCamera& view;
  const FrameSettings& settings;
  const gpu::GpuMesh& mesh;      // This frame's level of detail (shadows and eye alike).
  const TriangleMesh& cpu_mesh;  // The same level of detail on the CPU.
  const gpu::Drawable& points;   // The fused cloud; no vertices without one.
  const std::vector<Eigen::Vector3f>& cloud_positions;  // Its points on the CPU.
  Eigen::Vector4d light;            // LightVector(settings.light).
  Eigen::Matrix4f clip_from_world;  // The eye's.
  float ground_band = 0;            // GroundBand(scene): the ground's thickness (scene units).
  // NDC depth of the light's and the projectors' maps: kZeroToOne where glClipControl exists
  // (it is set so outside the eye's pass of a frame without reverse-Z).
  DepthRange range = DepthRange::kMinusOneToOne;
  bool reverse_z = false;  // The eye's depth is reverse-Z this frame (cleared to 0, GL_GREATER).
  bool hdr = false;        // The frame is drawn into the float frame, then tone-mapped.

  bool HasMesh() const { return mesh.triangles > 0; }
  // Window depth from NDC depth (scale, offset), for the shaders' comparisons.
  Eigen::Vector2f NdcToDepth() const;
  // The eye's depth test: nearer passes; nearer or equal for a second pass over the same
  // geometry.
  GLenum DepthLess() const { return reverse_z ? GL_GREATER : GL_LESS; }
  GLenum DepthLessOrEqual() const { return reverse_z ? GL_GEQUAL : GL_LEQUAL; }

  // The mesh's positions, by index, through the depth program (bound by the caller).
  void DrawMeshDepth() const;
  // What casts shadows and occludes projectors, through `program` (bound by the caller): the
  // mesh when there is one, else the points (`program` sizes them). The mesh goes as positions
  // alone when `depth_only`, else as caster triangles with face normals and heights above the
  // ground (planar shadows).
  void DrawCasters(const GlProgram& program, bool depth_only) const;
};

}  // namespace parallax

#pragma once
// The surfaces as the eye sees them: the mesh (after a depth pre-pass) and the points through
// the surface program, lit with Blinn-Phong (or the matcap's specular), textured by the atlas or
// the projected photos, shadowed as the frame's shadow method says. One program per variant,
// compiled on first use. Needs a current GL context.
#include <map>
#include <optional>
#include <span>
#include <tuple>

#include <Eigen/Core>

#include "viewer/depth_pass.h"
#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/projectors.h"

namespace parallax {

// What the surface program reads from the other passes of the frame.
struct SurfaceInputs {
  Eigen::Matrix4f shadow_from_world;     // ShadowMapPass::ShadowFromWorld.
  std::span<const Projector> projectors;  // Projectors::SetUp; empty but in projective mode.
  Eigen::Vector4f ground;                 // PlanarShadowPass::Ground, for its redraw.
  float ground_tolerance = 0;
};

class SurfacePass {
 public:
  // Draws the frame's mesh and points as `shadow` says (a planar or volume redraw: where the
  // stencil passes, without the depth pre-pass).
  void Draw(const FrameContext& frame, SurfaceShadow shadow, const SurfaceInputs& inputs, const DepthPass& depth);

 private:
  // Where a fragment's albedo comes from (the shader's ALBEDO_SOURCE).
  enum class Albedo { kAtlas = 0, kProjective = 1, kShaded = 2, kPointColors = 3, kMatcap = 4 };

  // The program of a variant, compiled on first use.
  const GlProgram& Program(Albedo albedo, SurfaceShadow shadow, int pcf_radius, bool hdr);
  // Binds `program` and sets the frame's uniforms.
  void Use(const GlProgram& program, const FrameContext& frame, const SurfaceInputs& inputs) const;
  // The mesh, after its depth alone where that saves shading, then the points.
  void DrawMesh(const FrameContext& frame, Albedo albedo, SurfaceShadow shadow, const SurfaceInputs& inputs,
                const DepthPass& depth);
  void DrawPoints(const FrameContext& frame, Albedo albedo, SurfaceShadow shadow, const SurfaceInputs& inputs);
  // The sphere map for the frame's light as the camera sees it, made again when that changes.
  void UpdateMatcap(const FrameContext& frame);

  // By (albedo, shadow, PCF radius, float output).
  std::map<std::tuple<int, int, int, bool>, GlProgram> programs_;
  GlTexture matcap_;
  // What `matcap_` was made for: the light in camera coordinates, specular, shininess.
  std::optional<std::tuple<Eigen::Vector3d, float, float>> matcap_key_;
};

}  // namespace parallax

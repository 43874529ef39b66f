#include "viewer/shadow_map_pass.h"

namespace parallax {
namespace {

// The light's clip_from_world. A directional light's map covers what it sees of the geometry
// drawn but its outermost half percent (its resolution is not spent on outliers), a point
// light's the robust extent; the depth range holds everything, so no caster is clipped away.
Eigen::Matrix4f LightMatrix(const FrameContext& frame) {
  const LightSettings& light = frame.settings.light;
  const ViewerScene& scene = frame.scene;
  if (light.type == LightKind::kPoint) return PointLightMatrix(light.position, scene.extent, scene.bounds, frame.range);
  return DirectionalLightMatrix(light.direction, frame.HasMesh() ? frame.cpu_mesh.vertices : frame.cloud_positions,
                                scene.bounds, frame.range);
}

}  // namespace

ShadowMapPass::ShadowMapPass() { map_.Resize(1, 1); }

SurfaceShadow ShadowMapPass::Update(const FrameContext& frame, const DepthPass& depth) {
  const FrameSettings& settings = frame.settings;
  if (settings.shadows != ShadowMode::kMap && settings.shadows != ShadowMode::kPcf) return SurfaceShadow::kNone;
  const Eigen::Matrix4f light_matrix = LightMatrix(frame);
  // PCF taps up to r texels away compare against the centre's depth: more slope bias.
  const float slope_bias = settings.shadows == ShadowMode::kPcf ? 1.5f + static_cast<float>(settings.pcf_radius) : 1.5f;
  const Key key{light_matrix, settings.shadow_map_size, slope_bias, &frame.mesh};
  if (key_ != key) {
    map_.Resize(settings.shadow_map_size, settings.shadow_map_size);
    depth.RenderMap(map_, light_matrix, frame, slope_bias);
    key_ = key;
  }
  shadow_from_world_ = light_matrix;
  return settings.shadows == ShadowMode::kMap ? SurfaceShadow::kMap : SurfaceShadow::kPcf;
}

size_t ShadowMapPass::Bytes() const {
  return static_cast<size_t>(map_.width) * static_cast<size_t>(map_.height) * sizeof(float);
}

}  // namespace parallax

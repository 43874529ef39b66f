#pragma once
// The shadow map (ShadowMode::kMap and kPcf): the casters' depth as the light sees them, which
// the surface program compares each fragment against. The scene is fixed, so the map is
// rendered again only when what it was rendered with changes: moving the eye costs nothing
// here. Needs a current GL context.
#include <cstddef>
#include <optional>

#include <Eigen/Core>

#include "viewer/depth_pass.h"
#include "viewer/frame_context.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class ShadowMapPass {
 public:
  // Holds a 1x1 map until the first shadowed frame: the comparison sampler must hold a depth
  // texture even when unused.
  ShadowMapPass();

  // For kMap and kPcf, renders the map when the light, its size, the PCF bias or the level of
  // detail changed; returns how the surface program reads it (kNone for the other modes).
  SurfaceShadow Update(const FrameContext& frame, const DepthPass& depth);

  GLuint Texture() const { return map_.texture.Get(); }
  // The light's clip_from_world of the last shadow-mapped frame (identity before one).
  const Eigen::Matrix4f& ShadowFromWorld() const { return shadow_from_world_; }
  // GPU memory of the map (bytes).
  size_t Bytes() const;

 private:
  // What the map was rendered with; the same key, the same map.
  struct Key {
    Eigen::Matrix4f light_clip_from_world;
    int size = 0;
    float slope_bias = 0;
    const gpu::GpuMesh* casters = nullptr;  // The level of detail drawn into it.
    bool operator==(const Key& other) const = default;
  };

  gpu::DepthTarget map_;
  std::optional<Key> key_;  // Absent until the map holds a rendering.
  Eigen::Matrix4f shadow_from_world_ = Eigen::Matrix4f::Identity();
};

}  // namespace parallax

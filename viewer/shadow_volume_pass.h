#pragma once
// Shadow volumes (ShadowMode::kVolume), z-fail ("Carmack's reverse"): the volume of
// viewer/shadow_volume.h, built on the CPU for one light, is counted in the stencil behind the
// visible surface, and the surfaces are drawn again, unlit, where the count is not zero. The
// volume is built again only when the light or the level of detail changes. Needs a current GL
// context.
#include <cstddef>
#include <functional>
#include <optional>

#include <Eigen/Core>

#include "geometry/obj.h"
#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class ShadowVolumePass {
 public:
  // Throws std::runtime_error if the program does not compile.
  ShadowVolumePass();

  // Counts the frame's volume in the stencil, then calls `redraw_unlit` to draw the surfaces
  // again (SurfaceShadow::kVolumeRedraw) where the count is not zero. Needs a mesh.
  void Draw(const FrameContext& frame, const std::function<void()>& redraw_unlit);

  // GPU memory of the volume's vertices (bytes); its stencil is the frame's.
  size_t Bytes() const;

 private:
  // What the volume was built for; the same key, the same volume.
  struct Key {
    Eigen::Vector4d light;
    const TriangleMesh* casters = nullptr;
    bool operator==(const Key& other) const { return light == other.light && casters == other.casters; }
  };
  // Builds the volume for the frame's light and mesh unless it holds it already.
  void Update(const FrameContext& frame);

  GlProgram program_;
  gpu::HomogeneousTriangles volume_;
  std::optional<Key> key_;  // Absent until the volume is built.
};

}  // namespace parallax

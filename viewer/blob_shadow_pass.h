#pragma once
// Blob shadows (ShadowMode::kBlob) on the GPU: the blobs of viewer/blob_shadows.h as one quad
// each on the ground, their soft texture multiplied into the frame. The objects are found once;
// the quads are placed again when the light changes. Needs a current GL context.
#include <cstddef>
#include <optional>

#include <Eigen/Core>

#include "viewer/blob_shadows.h"
#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"

namespace parallax {

class BlobShadowPass {
 public:
  // Throws std::runtime_error if the program does not compile.
  BlobShadowPass();

  // Darkens the ground under each object of the scene's full mesh. Needs frame.scene.ground.
  void Draw(const FrameContext& frame);

  // GPU memory of the texture and the quads (bytes); 0 before the first blob frame.
  size_t Bytes() const;

 private:
  // Makes the texture and finds the objects on the first call, places the quads for a new light.
  void Update(const FrameContext& frame);

  GlProgram program_;
  GlTexture texture_;
  BlobCasters casters_;   // The objects on the ground (of the full mesh).
  gpu::Drawable quads_;   // Two triangles a blob, placed for `light_`.
  std::optional<Eigen::Vector4d> light_;
};

}  // namespace parallax

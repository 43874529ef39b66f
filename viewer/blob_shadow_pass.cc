#include "viewer/blob_shadow_pass.h"

#include <utility>
#include <vector>

#include "viewer/shaders.h"

namespace parallax {
namespace {

constexpr int kMaxBlobs = 16;
constexpr int kBlobTextureSize = 64;

// Two triangles a blob, the texture coordinate (s, t) in [-1, 1]^2 over its ellipse.
std::vector<gpu::Vertex> BlobQuads(const std::vector<Blob>& blobs) {
  std::vector<gpu::Vertex> corners;
  for (const Blob& b : blobs) {
    for (const auto& [s, t] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}}) {
      const Eigen::Vector3f p = b.centre + static_cast<float>(s) * b.axis_u + static_cast<float>(t) * b.axis_v;
      corners.push_back({{p.x(), p.y(), p.z()}, {}, {static_cast<float>(s), static_cast<float>(t)}, {}});
    }
  }
  return corners;
}

}  // namespace

BlobShadowPass::BlobShadowPass() : program_("blob shadow", shaders::kBlobVertex, shaders::kBlobFragment) {}

void BlobShadowPass::Update(const FrameContext& frame) {
  const ViewerScene& scene = frame.scene;
  if (texture_.Get() == 0) {
    gpu::UploadFloatTexture(texture_, BlobTexture(kBlobTextureSize), kBlobTextureSize, gpu::kScratchUnit);
    // Objects are what rises five times the ground band above it (a reconstructed ground's
    // bumps do not join them into one); a footprint wider than a third of the scene is a wall
    // or a building around it.
    casters_ = FindBlobCasters(scene.mesh, *scene.ground, 5 * frame.ground_band, 0.35f * scene.Radius(), kMaxBlobs);
  }
  if (light_ != frame.light) {
    quads_ = gpu::Upload(BlobQuads(PlaceBlobs(scene.mesh, casters_, *scene.ground, frame.light, frame.ground_band)));
    light_ = frame.light;
  }
}

// Each quad is multiplied into the color and the visibility, lifted towards the eye by the
// ground band so that the reconstructed ground's bumps do not hide it; objects nearer than that
// keep their color.
void BlobShadowPass::Draw(const FrameContext& frame) {
  Update(frame);
  glActiveTexture(GL_TEXTURE0 + gpu::kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, texture_.Get());
  glActiveTexture(GL_TEXTURE0);
  program_.Use();
  program_.Set("u_clip_from_world", frame.clip_from_world);
  program_.Set("u_eye", Eigen::Vector3f(CameraCenter(frame.view.cam_from_world).cast<float>()));
  program_.Set("u_lift", frame.ground_band);
  program_.Set("u_blob", gpu::kScratchUnit);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ZERO, GL_SRC_COLOR);
  glBindVertexArray(quads_.vao.Get());
  glDrawArrays(GL_TRIANGLES, 0, quads_.count);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
}

size_t BlobShadowPass::Bytes() const {
  if (texture_.Get() == 0) return 0;
  return kBlobTextureSize * kBlobTextureSize * sizeof(float) + static_cast<size_t>(quads_.count) * sizeof(gpu::Vertex);
}

}  // namespace parallax

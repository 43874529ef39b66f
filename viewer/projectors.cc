#include "viewer/projectors.h"

#include <algorithm>
#include <cstdint>

#include "core/image.h"

namespace parallax {

Projectors::Projectors() {
  for (gpu::DepthTarget& target : depth_maps_) target.Resize(1, 1);
}

GLuint Projectors::Photo(const ViewerScene& scene, int source) {
  auto found = photos_.find(source);
  if (found == photos_.end()) {
    found = photos_.emplace(source, gpu::UploadSrgbTexture(ReadImage(scene.sources[source].image_path))).first;
  }
  return found->second.Get();
}

std::span<const Projector> Projectors::SetUp(const FrameContext& frame, const std::vector<int>& sources,
                                             const DepthPass& depth) {
  const ViewerScene& scene = frame.scene;
  for (size_t k = 0; k < sources.size(); ++k) {
    const ViewerSource& source = scene.sources[sources[k]];
    const Eigen::Vector2d range = DepthBounds(scene.bounds, source.cam_from_world);
    const Eigen::Matrix4f clip_from_world =
        PerspectiveProjection(source.camera, range[0], range[1], frame.range) * ViewMatrix(source.cam_from_world);
    depth_maps_[k].Resize(static_cast<int>(std::min<uint64_t>(source.camera.width, 4096)),
                          static_cast<int>(std::min<uint64_t>(source.camera.height, 4096)));
    depth.RenderMap(depth_maps_[k], clip_from_world, frame, 0.0f);
    const GLuint photo = Photo(scene, sources[k]);
    glActiveTexture(GL_TEXTURE0 + gpu::kPhotoUnit + k);
    glBindTexture(GL_TEXTURE_2D, photo);
    glActiveTexture(GL_TEXTURE0 + gpu::kProjectorDepthUnit + k);
    glBindTexture(GL_TEXTURE_2D, depth_maps_[k].texture.Get());
    projectors_[k] = {clip_from_world, CameraCenter(source.cam_from_world).cast<float>(),
                      Eigen::Vector3f(source.gain[0], source.gain[1], source.gain[2])};
  }
  glActiveTexture(GL_TEXTURE0);
  return {projectors_.data(), sources.size()};
}

}  // namespace parallax

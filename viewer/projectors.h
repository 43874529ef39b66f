#pragma once
// Projective texturing (TextureMode::kProjective): source photos projected from their cameras
// onto the surfaces, each occluded by its own depth map (a shadow map from the projector). The
// photos are uploaded on first use and kept, by source index; the depth maps are rendered every
// frame. Needs a current GL context.
#include <array>
#include <map>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "viewer/depth_pass.h"
#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"

namespace parallax {

// One projecting source camera as the surface program reads it.
struct Projector {
  Eigen::Matrix4f clip_from_world = Eigen::Matrix4f::Identity();
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  // World.
  Eigen::Vector3f gain = Eigen::Vector3f::Ones();    // The photo's color gain, linear RGB.
};

class Projectors {
 public:
  // Holds 1x1 depth maps until the first projective frame: the comparison samplers must hold a
  // depth texture even when unused.
  Projectors();

  // For each of `sources` (indices into the scene's sources, at most kMaxProjectors): renders
  // its depth map, binds it and the photo to the projector's texture units, and returns them in
  // that order. Throws if a photo cannot be read.
  std::span<const Projector> SetUp(const FrameContext& frame, const std::vector<int>& sources,
                                   const DepthPass& depth);

 private:
  // The photo of a source, uploaded on first use.
  GLuint Photo(const ViewerScene& scene, int source);

  std::array<gpu::DepthTarget, kMaxProjectors> depth_maps_;
  std::array<Projector, kMaxProjectors> projectors_;
  std::map<int, GlTexture> photos_;  // By source index.
};

}  // namespace parallax

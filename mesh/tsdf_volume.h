#pragma once
// A truncated signed-distance volume fused from depth maps (Curless and Levoy 1996, as
// KinectFusion and Open3D fuse them): each voxel holds the weighted mean of its distance to the
// surface each depth map saw, measured along the camera's axis (the map's depth at the voxel's
// pixel less the voxel's depth), divided by the truncation and clipped to [-1, 1]: positive in
// the space a camera saw through, negative behind the surface. Voxels live in blocks of 8^3
// made only where some depth map puts a surface within the truncation, so memory follows the
// surface, not the scene's box. The surface is the zero level by marching cubes, kept where
// every corner was seen by `min_weight` depth maps' worth of weight. The same maps in the same
// order give the same mesh.
#include <array>
#include <cstdint>
#include <map>

#include "core/camera.h"
#include "core/depth_map.h"
#include "core/pose.h"
#include "geometry/triangle_mesh.h"

namespace parallax {

struct TsdfOptions {
  double voxel_size = 0;  // Scene units.
  double truncation = 0;  // Half the band around the surface that depth maps write, scene units.
  // Throws BadInputError unless both are positive and finite and the truncation is at least a
  // voxel (thinner, the band would miss voxels on either side of the surface).
  void Check() const;
};

class TsdfVolume {
 public:
  static constexpr int kBlockSide = 8;

  explicit TsdfVolume(const TsdfOptions& options);

  // Fuses a depth map (0: no depth) seen by a pinhole `camera` of its size at `cam_from_world`,
  // each depth weighed `weight`. Throws BadInputError when the camera is not a pinhole of the
  // map's size.
  void Integrate(const Camera& camera, const Rigid3d& cam_from_world, const DepthMap& depth, float weight = 1);

  // The zero level where the voxels at all eight corners of a cell hold at least `min_weight`.
  TriangleMesh Mesh(float min_weight) const;

  size_t Blocks() const { return blocks_.size(); }
  size_t Bytes() const { return blocks_.size() * sizeof(Block); }

 private:
  struct Voxel {
    float distance = 0;  // Truncated, in [-1, 1].
    float weight = 0;
  };
  using Block = std::array<Voxel, kBlockSide * kBlockSide * kBlockSide>;
  using BlockIndex = std::array<int, 3>;

  TsdfOptions options_;
  std::map<BlockIndex, Block> blocks_;  // Ordered: the mesh does not depend on a hash's order.
};

}  // namespace parallax

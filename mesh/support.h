#pragma once
// Floaters: the connected pieces of a mesh that the depth maps do not support. Poisson closes
// blobs around stray fused points (a pedestrian, a reflection, a mismatch one pair agreed on);
// trimming keeps them, since they lie near their own points. A piece stays when at least
// `min_views` depth maps see it where they measured their surface.
#include <cstddef>
#include <functional>
#include <vector>

#include "core/camera.h"
#include "core/depth_map.h"
#include "core/pose.h"
#include "geometry/triangle_mesh.h"

namespace parallax {

struct SupportView {
  Camera camera;
  Rigid3d cam_from_world;
  // The view's depth map (any size: pixels are scaled from the camera's), read when needed:
  // one is in memory at a time.
  std::function<DepthMap()> load_depth;
};

struct SupportOptions {
  // A vertex lies on a depth map's surface when its depth there is within this share of the
  // map's depth at its pixel (loose: the ground is seen at grazing angles, where the depth
  // changes fast across a pixel) ...
  double depth_tolerance = 0.05;
  // ... and a depth map supports a piece when at least one vertex lies on its surface and no
  // more of the vertices it sees lie in front of its surface (in space it saw through) than
  // on it.
  int min_views = 2;
  void Check() const;
};

struct SupportSummary {
  size_t pieces = 0;
  size_t dropped_pieces = 0;
  size_t dropped_triangles = 0;
};

// `mesh` without the pieces fewer than options.min_views of `views` support (and without the
// vertices they alone used; normals and colors follow their vertices). Deterministic.
TriangleMesh DropUnsupportedPieces(const TriangleMesh& mesh, const std::vector<SupportView>& views,
                                   const SupportOptions& options, SupportSummary& summary);

}  // namespace parallax

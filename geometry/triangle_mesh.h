#pragma once
// The one triangle mesh of parallax: positions and triangles, and the attributes a mesh may
// carry. A PLY cloud has per-vertex normals and colors (geometry/ply.h); a textured mesh has
// per-corner texture coordinates and their atlas (geometry/obj.h); synth's shapes have neither.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/image.h"

namespace parallax {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;  // Vertex indices; empty for a point cloud.
  std::vector<Eigen::Vector3f> normals;    // One per vertex, or empty.
  std::vector<std::array<uint8_t, 3>> colors;  // sRGB, one per vertex, or empty.
  // Texture coordinates of each triangle's three corners (3 per triangle), OBJ convention:
  // u to the right, v up, (0, 0) the bottom-left corner of the atlas; or empty.
  std::vector<Eigen::Vector2f> corner_uvs;
  Image atlas;  // sRGB, 3 channels; empty without corner_uvs.
};

}  // namespace parallax

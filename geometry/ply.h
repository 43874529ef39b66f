#pragma once
// Reading binary little-endian PLY files: our fused clouds, COLMAP's fused.ply and the meshes
// `colmap poisson_mesher` writes. Only what the pipeline needs: vertex positions (float x, y, z
// as the first three vertex properties, any others skipped) and, when present, triangle faces
// (a `vertex_indices` list). Every count and index is checked against the file before use.
#include <filesystem>
#include <vector>

#include <Eigen/Core>

namespace parallax {

struct PlyMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;  // Empty for a point cloud.
};

// Throws BadInputError naming the file for anything else (ASCII or big-endian files, a
// truncated body, faces that are not triangles, indices out of range, NaN or Inf positions).
PlyMesh ReadPly(const std::filesystem::path& path);

}  // namespace parallax

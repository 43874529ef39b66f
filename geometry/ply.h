#pragma once
// Reading binary little-endian PLY files: our fused clouds, COLMAP's fused.ply and the meshes
// `colmap poisson_mesher` writes. Only what parallax needs: vertex positions (float x, y, z as
// the first three vertex properties), normals (float nx, ny, nz) and colors (uchar red, green,
// blue) when present, any other property skipped, and triangle faces (a `vertex_indices`
// list). Every count and index is checked against the file before use.
#include <filesystem>
#include <vector>

#include "geometry/triangle_mesh.h"

namespace parallax {

// Throws BadInputError naming the file for anything else (ASCII or big-endian files, a
// truncated body, faces that are not triangles, indices out of range, NaN or Inf positions).
TriangleMesh ReadPly(const std::filesystem::path& path);

}  // namespace parallax

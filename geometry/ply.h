#pragma once
// Reading binary little-endian PLY files: our fused clouds, COLMAP's fused.ply and the meshes
// `colmap poisson_mesher` writes, and the textured meshes of OpenMVS's TextureMesh. Only what
// parallax needs: vertex positions (float x, y, z as the first three vertex properties),
// normals (float nx, ny, nz) and colors (uchar red, green, blue) when present, any other
// property skipped, and triangle faces (a `vertex_indices` list) with, when present, their
// corners' texture coordinates (a `texcoord` list of 6 floats, OBJ convention) and the one
// texture a `comment TextureFile NAME` line names beside the file. Every count and index is
// checked against the file before use.
#include <filesystem>
#include <vector>

#include "geometry/triangle_mesh.h"

namespace parallax {

// What a NaN or Inf vertex position does: refuse the file, or drop the triangles that use the
// vertex (colmap's poisson_mesher writes one now and then) and leave the vertex unreferenced.
enum class NonFiniteVertices { kRefuse, kDropTheirTriangles };

// Throws BadInputError naming the file for anything else (ASCII or big-endian files, a
// truncated body, faces that are not triangles, indices out of range, NaN or Inf positions
// unless they are dropped).
TriangleMesh ReadPly(const std::filesystem::path& path,
                     NonFiniteVertices non_finite = NonFiniteVertices::kRefuse);

}  // namespace parallax

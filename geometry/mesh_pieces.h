#pragma once
// A triangle mesh's connected pieces, and the mesh with some of its triangles left out.
#include <cstdint>
#include <vector>

#include "geometry/triangle_mesh.h"

namespace parallax {

// The piece of every vertex: vertices joined by triangle edges share a number, numbered
// 0, 1, ... in the order of their first vertex; a vertex no triangle uses is a piece of its
// own. `piece_count` receives the number of pieces. Pure.
std::vector<int> PieceOfEachVertex(const TriangleMesh& mesh, int& piece_count);

// The mesh with only the triangles whose `keep` is nonzero (one entry per triangle), and only
// the vertices (with their normals and colors) those triangles use, in their first use's order.
// Texture coordinates and the atlas are not carried. Throws InternalError when `keep`
// has another size than the triangles.
TriangleMesh KeepTriangles(const TriangleMesh& mesh, const std::vector<uint8_t>& keep);

}  // namespace parallax

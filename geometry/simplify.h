#pragma once
// Mesh simplification for display: the viewer needs no more triangles than the pixels they
// cover, and on a CPU rasteriser every triangle costs (vertex shading, setup, binning).
#include <cstddef>

#include "geometry/ply.h"

namespace parallax {

// At most `max_triangles` triangles approximating `mesh`, by vertex clustering with quadric
// representatives (Lindstrom 2000): the vertices in each cell of a uniform grid merge into the
// point that best fits the planes of their triangles, and triangles whose corners fall into
// fewer than three distinct cells disappear. The grid is the finest whose result fits the
// budget. Returns `mesh` unchanged when it already fits. Throws InternalError for a
// budget below 1 or triangles indexing outside the vertices.
TriangleMesh SimplifyMesh(const TriangleMesh& mesh, size_t max_triangles);

}  // namespace parallax

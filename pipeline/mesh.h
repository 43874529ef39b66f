#pragma once
// The mesh stage of `parallax reconstruct`: fused cloud -> `colmap poisson_mesher` (screened
// Poisson, watertight) -> trimmed to where the cloud has data -> textured from the photos ->
// <ws>/mesh/mesh.obj|.mtl|.png.
#include <filesystem>

#include "core/progress.h"
#include "pipeline/colmap.h"
#include "pipeline/quality.h"
#include "pipeline/texture.h"

namespace parallax {

struct MeshOptions {
  // Octree depth of the Poisson solve: cells of (scene extent / 2^depth).
  int poisson_depth = 10;
  // Poisson closes the surface everywhere, also where no photo saw anything; a triangle is
  // kept only if each of its corners lies within this many octree cells of a fused point.
  double max_cells_from_data = 2;
  TextureOptions texture;
  void Check() const;
};

// fast: depth 9; balanced: 10; best: 11 (each level about 4x the triangles and 2x the time).
MeshOptions MeshOptionsFor(Quality quality);

struct MeshSummary {
  size_t poisson_triangles = 0;
  size_t triangles = 0;  // After trimming.
  size_t vertices = 0;
  int texels_per_edge = 0;
  size_t untextured_triangles = 0;
  int atlas_width = 0, atlas_height = 0;
};

// Reads <ws>/fused.ply, <ws>/sparse and <ws>/images; writes <ws>/mesh/ (atomically) and the
// raw Poisson mesh to <ws>/mesh_poisson.ply. Throws BadInputError for an empty cloud,
// ToolError if colmap fails.
MeshSummary MeshWorkspace(const std::filesystem::path& workspace, const Colmap& colmap,
                          const MeshOptions& options, Progress& progress);

}  // namespace parallax

#pragma once
// The mesh stage's options and summary, and its own step between Poisson and texture: fused
// cloud -> screened Poisson surface (watertight) -> trimmed to where the cloud has data
// (TrimToData) -> without floaters (mesh/support.h) -> textured from the photos
// (mesh/texture.h), and a simplified copy for display. The stage over a workspace, which runs
// `colmap poisson_mesher` and writes <ws>/mesh/ and <ws>/mesh_display/, is
// pipeline/mesh_workspace.h.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "core/quality.h"
#include "geometry/triangle_mesh.h"
#include "mesh/support.h"
#include "mesh/texture.h"

namespace parallax {

// What makes the surface: screened Poisson over the fused cloud (colmap's poisson_mesher,
// trimmed to the data), or the depth maps fused into a truncated signed-distance volume and its
// zero level by marching cubes (mesh/tsdf_volume.h).
enum class Mesher { kPoisson, kTsdf };

struct MeshOptions {
  Mesher mesher = Mesher::kPoisson;
  // kTsdf: the voxel in depth-map pixels at the views' median depth, the truncation in voxels,
  // and how many depth maps must have written each corner of a cell for it to make surface
  // (docs/mesh.md: on the courtyard 2 px voxels gave 7 times the triangles for 0.1 dB, a weight
  // of 1 fragments where maps disagree).
  double tsdf_voxel_pixels = 4;
  double tsdf_truncation_voxels = 3;
  float tsdf_min_weight = 2;
  // Octree depth of the Poisson solve: cells of (scene extent / 2^depth).
  int poisson_depth = 10;
  // Poisson closes the surface everywhere, also where no photo saw anything; a triangle is
  // kept only if each of its corners lies within this many octree cells of a fused point.
  double max_cells_from_data = 2;
  // COLMAP's density trim (--PoissonMeshing.trim): removes the surface where the samples are
  // sparser than this, in log2 of the sample density. Its default, 10, suits a cloud fused at
  // the photos' full size; the mesh stage lowers it by log2 of the share of the photos' pixels
  // the cloud was fused from (docs/mesh.md).
  double poisson_trim = 10;
  // The viewer's level of detail: a mesh with more triangles also gets a simplified copy with
  // at most this many (about one per 28 pixels of a 1280x720 view), textured on its own, which
  // the viewer draws when the full mesh would have more triangles than the pixels need.
  size_t display_max_triangles = 32768;
  SupportOptions support;  // Which pieces of the trimmed surface are floaters.
  TextureOptions texture;
  void Check() const;
};

// fast: depth 9; balanced: 10; best: 11 (each level about 4x the triangles and 2x the time).
MeshOptions MeshOptionsFor(Quality quality);

struct MeshSummary {
  size_t poisson_triangles = 0;  // The raw surface's: Poisson's, or the volume's (tsdf).
  size_t triangles = 0;  // After trimming and dropping floaters.
  size_t vertices = 0;
  int texels_per_edge = 0;
  size_t untextured_triangles = 0;
  int atlas_width = 0, atlas_height = 0;
  size_t display_triangles = 0;  // 0: the mesh is small enough to display as it is.
  size_t pieces = 0;             // Connected pieces of the trimmed surface ...
  size_t dropped_pieces = 0;     // ... the floaters among them ...
  size_t dropped_triangles = 0;  // ... and their triangles.
  std::string mesher = "poisson";
  double voxel_size = 0;  // tsdf: scene units.
  size_t voxel_blocks = 0;  // tsdf: blocks of 8^3 voxels made.
};

// <ws>/mesh/summary.json and report.json's "mesh" section.
void to_json(nlohmann::json& json, const MeshSummary& mesh);
void from_json(const nlohmann::json& json, MeshSummary& mesh);

// `surface` (Poisson's, of the cloud `points` at options.poisson_depth) without the triangles
// that have a corner farther than options.max_cells_from_data octree cells from every point,
// and without the vertices no triangle uses; the octree cell is the points' bounding cube over
// 2^poisson_depth. Non-finite vertices count as far. Throws InternalError for no points.
TriangleMesh TrimToData(const TriangleMesh& surface, const std::vector<Eigen::Vector3f>& points,
                        const MeshOptions& options);

}  // namespace parallax

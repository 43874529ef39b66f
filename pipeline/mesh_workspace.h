#pragma once
// The mesh stage over a workspace: <ws>/fused.ply -> `colmap poisson_mesher` (screened Poisson,
// watertight) -> trimmed to where the cloud has data (mesh/poisson.h), or with Mesher::kTsdf
// <ws>/depth's maps fused into a signed-distance volume and its zero level -> without the pieces
// <ws>/depth's maps do not support (mesh/support.h) -> textured from the photos of
// <ws>/images (mesh/texture.h) -> <ws>/mesh/mesh.obj|.mtl|.png|.glb, and a simplified copy for
// display -> <ws>/mesh_display/.
#include "colmap/runner.h"
#include "core/progress.h"
#include "core/workspace.h"
#include "mesh/poisson.h"

namespace parallax {

// Reads <ws>/fused.ply, <ws>/sparse, <ws>/depth, <ws>/images and <ws>/color_gains.json (when
// present); writes <ws>/mesh/ and <ws>/mesh_display/ (each atomically; the latter only for a mesh over
// the display budget, else it is removed) and the raw Poisson mesh to <ws>/mesh_poisson.ply.
// Throws BadInputError for an empty cloud, ToolError if colmap fails.
MeshSummary MeshWorkspace(const Workspace& workspace, const Colmap& colmap, const MeshOptions& options,
                          Progress& progress);

}  // namespace parallax

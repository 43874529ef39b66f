#pragma once
// A textured triangle mesh as one binary glTF 2.0 file (<ws>/mesh/mesh.glb): geometry, texture
// coordinates and the atlas in a single file that web viewers, Blender and three.js open.
#include <filesystem>
#include <string_view>

#include "geometry/triangle_mesh.h"

namespace parallax {

// Writes `mesh` (triangles with corner_uvs) to `path` through a temporary name, the atlas
// embedded as `atlas_png` (the PNG file's bytes). glTF gives each vertex one texture
// coordinate and the atlas gives each triangle corner its own, so every corner is a vertex of
// its own (no index buffer). The material is unlit (KHR_materials_unlit): the atlas already
// holds the photos' light. The scene's node turns the mesh half a turn about x, from COLMAP's
// frame (y down, cameras looking along +z) to glTF's (+y up). Throws InternalError for
// a mesh without triangles, without one texture coordinate per corner, or with a non-finite
// vertex.
void WriteGlb(const std::filesystem::path& path, const TriangleMesh& mesh, std::string_view atlas_png);

}  // namespace parallax

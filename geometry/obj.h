#pragma once
// A textured triangle mesh's files: Wavefront OBJ + MTL + PNG atlas, the format every mesh
// tool opens (<ws>/mesh/mesh.obj|.mtl|.png).
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "core/image.h"
#include "geometry/triangle_mesh.h"

namespace parallax {

// Writes <dir>/mesh.obj, mesh.mtl and mesh.png, and the same mesh as one binary glTF file,
// mesh.glb (geometry/glb.h), through a temporary folder renamed into place, so a reader never
// sees a mix of old and new files.
void WriteTexturedMesh(const std::filesystem::path& dir, const TriangleMesh& mesh);

// Reads an OBJ (tinyobjloader) with triangles whose corners all have texture coordinates, and
// the atlas its MTL names (map_Kd). Throws BadInputError naming the file, and the line where
// one is at fault, for anything else.
TriangleMesh ReadTexturedMesh(const std::filesystem::path& obj_path);

// Atlas color at `uv` (OBJ convention), through SampleBilinear (core/image_sampling.h).
Eigen::Vector3f SampleAtlas(const Image& atlas, const Eigen::Vector2f& uv);

}  // namespace parallax

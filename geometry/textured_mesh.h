#pragma once
// A triangle mesh with one texture atlas, and its files: Wavefront OBJ + MTL + PNG atlas, the
// format every mesh tool opens (<ws>/mesh/mesh.obj|.mtl|.png).
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "core/image.h"

namespace parallax {

struct TexturedMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  // Texture coordinates of each triangle's three corners (3 per triangle), OBJ convention:
  // u to the right, v up, (0, 0) the bottom-left corner of the atlas.
  std::vector<Eigen::Vector2f> corner_uvs;
  Image atlas;  // sRGB, 3 channels.
};

// Writes <dir>/mesh.obj, mesh.mtl and mesh.png through a temporary folder renamed into place,
// so a reader never sees a mix of old and new files.
void WriteTexturedMesh(const std::filesystem::path& dir, const TexturedMesh& mesh);

// Reads an OBJ with `v`, `vt` and triangular `f v/vt` lines and the atlas its MTL names
// (map_Kd). Throws BadInputError naming the file and line for anything malformed.
TexturedMesh ReadTexturedMesh(const std::filesystem::path& obj_path);

// Colour (first 3 channels) at a continuous pixel position (pixel centres at integer + 0.5),
// bilinear between pixel centres, clamped at the border.
Eigen::Vector3f SampleBilinear(const Image& image, const Eigen::Vector2f& pixel);

// Atlas colour at `uv` (OBJ convention), through SampleBilinear.
Eigen::Vector3f SampleAtlas(const Image& atlas, const Eigen::Vector2f& uv);

}  // namespace parallax

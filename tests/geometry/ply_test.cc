#include "geometry/ply.h"

#include <array>
#include <cstring>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// A binary PLY cloud of `positions` with, per vertex, a normal (0, 0, 1) and a color (i, 2i, 3i)
// where asked; a `value` property before the normals, which readers must skip.
std::string Cloud(const std::vector<Eigen::Vector3f>& positions, bool normals, bool colors) {
  std::string text = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                     std::to_string(positions.size()) +
                     "\nproperty float x\nproperty float y\nproperty float z\nproperty float value\n";
  if (normals) text += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) text += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  text += "end_header\n";
  for (size_t i = 0; i < positions.size(); ++i) {
    const float record[4] = {positions[i].x(), positions[i].y(), positions[i].z(), 7.0f};
    text.append(reinterpret_cast<const char*>(record), sizeof(record));
    if (normals) {
      const float normal[3] = {0, 0, 1};
      text.append(reinterpret_cast<const char*>(normal), sizeof(normal));
    }
    if (colors) {
      const unsigned char color[3] = {static_cast<unsigned char>(i), static_cast<unsigned char>(2 * i),
                                       static_cast<unsigned char>(3 * i)};
      text.append(reinterpret_cast<const char*>(color), sizeof(color));
    }
  }
  return text;
}

TEST(Ply, ReadsNormalsAndColorsWhereTheCloudHasThem) {
  const TempDir dir;
  const std::vector<Eigen::Vector3f> positions = {{1, 2, 3}, {4, 5, 6}, {-1, 0, 1}};
  WriteFileAtomically(dir.Path() / "full.ply", Cloud(positions, true, true));
  const TriangleMesh full = ReadPly(dir.Path() / "full.ply");
  ASSERT_EQ(full.vertices.size(), 3u);
  ASSERT_EQ(full.normals.size(), 3u);
  ASSERT_EQ(full.colors.size(), 3u);
  EXPECT_EQ(full.vertices[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_EQ(full.normals[2], Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(full.colors[2], (std::array<uint8_t, 3>{2, 4, 6}));
  EXPECT_TRUE(full.triangles.empty());

  WriteFileAtomically(dir.Path() / "bare.ply", Cloud(positions, false, false));
  const TriangleMesh bare = ReadPly(dir.Path() / "bare.ply");
  EXPECT_EQ(bare.vertices[2], Eigen::Vector3f(-1, 0, 1));
  EXPECT_TRUE(bare.normals.empty());
  EXPECT_TRUE(bare.colors.empty());
}

// Four vertices, the third NaN, and two triangles: (0, 1, 3) and (1, 2, 3), which uses it.
std::string MeshWithANanVertex() {
  std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float vertices[4][3] = {{0, 0, 0}, {1, 0, 0}, {nan, 0, 0}, {0, 1, 0}};
  text.append(reinterpret_cast<const char*>(vertices), sizeof(vertices));
  for (const std::array<int, 3>& face : {std::array<int, 3>{0, 1, 3}, std::array<int, 3>{1, 2, 3}}) {
    text.push_back(3);
    text.append(reinterpret_cast<const char*>(face.data()), 3 * sizeof(int));
  }
  return text;
}

TEST(Ply, ANanVertexIsRefusedOrItsTrianglesDropped) {
  const TempDir dir;
  WriteFileAtomically(dir.Path() / "mesh.ply", MeshWithANanVertex());
  EXPECT_THROW(ReadPly(dir.Path() / "mesh.ply"), BadInputError);
  const TriangleMesh kept = ReadPly(dir.Path() / "mesh.ply", NonFiniteVertices::kDropTheirTriangles);
  ASSERT_EQ(kept.triangles.size(), 1u);
  EXPECT_EQ(kept.triangles[0], Eigen::Vector3i(0, 1, 3));
}

}  // namespace
}  // namespace parallax

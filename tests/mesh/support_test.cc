// Floaters: the pieces of a mesh the depth maps do not support, on analytic scenes, and the
// pieces of a mesh themselves.
#include "mesh/support.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sparse_model.h"
#include "geometry/mesh_pieces.h"

namespace parallax {
namespace {

constexpr float kWallDepth = 10;

// A camera at (x, 0, 0) looking down +z at the wall z = 10, whose depth map it measured:
// 100x100 pixels, 100 px focal length, so it sees x in [x - 5, x + 5] on the wall.
SupportView WallView(double x) {
  SupportView view;
  view.camera = MakePinholeCamera(1, 100, 100, 100, 100, 50, 50);
  view.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-x, 0, 0));
  view.load_depth = [] {
    DepthMap depth(100, 100);
    std::fill(depth.Values().begin(), depth.Values().end(), kWallDepth);
    return depth;
  };
  return view;
}

// A square of 2 x 2 quads at depth z, from (x, y) to (x + size, y + size): one piece.
void AddSquare(TriangleMesh& mesh, float x, float y, float size, float z) {
  const int first = static_cast<int>(mesh.vertices.size());
  for (int j = 0; j <= 2; ++j) {
    for (int i = 0; i <= 2; ++i) mesh.vertices.emplace_back(x + size * i / 2, y + size * j / 2, z);
  }
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const int a = first + j * 3 + i, b = a + 1, c = a + 3, d = c + 1;
      mesh.triangles.emplace_back(a, b, d);
      mesh.triangles.emplace_back(a, d, c);
    }
  }
}

TEST(MeshPieces, VerticesJoinedByTrianglesShareAPiece) {
  TriangleMesh mesh;
  AddSquare(mesh, 0, 0, 1, 5);
  AddSquare(mesh, 3, 0, 1, 5);
  mesh.vertices.emplace_back(9, 9, 9);  // Used by no triangle: a piece of its own.
  int pieces = 0;
  const std::vector<int> piece = PieceOfEachVertex(mesh, pieces);
  EXPECT_EQ(pieces, 3);
  for (int v = 0; v < 9; ++v) EXPECT_EQ(piece[static_cast<size_t>(v)], 0);
  for (int v = 9; v < 18; ++v) EXPECT_EQ(piece[static_cast<size_t>(v)], 1);
  EXPECT_EQ(piece[18], 2);
}

TEST(MeshPieces, KeptTrianglesTakeOnlyTheirVertices) {
  TriangleMesh mesh;
  AddSquare(mesh, 0, 0, 1, 5);
  AddSquare(mesh, 3, 0, 1, 5);
  mesh.normals.assign(mesh.vertices.size(), Eigen::Vector3f::UnitZ());
  std::vector<uint8_t> keep(mesh.triangles.size(), 0);
  for (size_t t = 8; t < 16; ++t) keep[t] = 1;  // The second square.
  const TriangleMesh kept = KeepTriangles(mesh, keep);
  ASSERT_EQ(kept.triangles.size(), 8u);
  ASSERT_EQ(kept.vertices.size(), 9u);
  EXPECT_EQ(kept.normals.size(), 9u);
  for (const Eigen::Vector3f& v : kept.vertices) EXPECT_GE(v.x(), 3);
  EXPECT_THROW(KeepTriangles(mesh, std::vector<uint8_t>(3, 1)), InternalError);
}

TEST(Support, FloatersInSeenFreeSpaceOrSeenByOneViewGoAndTheWallStays) {
  TriangleMesh mesh;
  AddSquare(mesh, -3, -3, 6, kWallDepth);          // The wall: all three views measured it.
  AddSquare(mesh, -0.5f, -0.5f, 1, 6);             // In front of it, in space the views saw through.
  AddSquare(mesh, -0.5f, -0.5f, 1, 14);            // Behind it: no view sees it.
  AddSquare(mesh, 5.5f, -0.5f, 0.4f, kWallDepth);  // On the wall's plane, in one view's frame only.
  const std::vector<SupportView> views = {WallView(-1), WallView(0), WallView(1)};

  SupportSummary summary;
  const TriangleMesh kept = DropUnsupportedPieces(mesh, views, SupportOptions{}, summary);
  EXPECT_EQ(summary.pieces, 4u);
  EXPECT_EQ(summary.dropped_pieces, 3u);
  EXPECT_EQ(summary.dropped_triangles, 24u);
  ASSERT_EQ(kept.triangles.size(), 8u);
  for (const Eigen::Vector3f& v : kept.vertices) {
    EXPECT_EQ(v.z(), kWallDepth);
    EXPECT_LE(v.x(), 3);
  }

  SupportOptions one_view;
  one_view.min_views = 1;
  EXPECT_EQ(DropUnsupportedPieces(mesh, views, one_view, summary).triangles.size(), 16u);
  EXPECT_EQ(summary.dropped_pieces, 2u);
}

TEST(Support, APieceHalfInFreeSpaceIsSupportedOnlyWhereMoreOfItLiesOnTheSurface) {
  // A square folded along x = 0: its left half on the wall, its right half 3 in front of it.
  TriangleMesh mesh;
  AddSquare(mesh, -1, -1, 2, kWallDepth);
  for (Eigen::Vector3f& v : mesh.vertices) {
    if (v.x() > 0) v.z() = kWallDepth - 3;
  }
  // 3 vertices at x = -1 on the surface, 3 at x = 0 on it, 3 at x = 1 in front: supported.
  SupportSummary summary;
  EXPECT_EQ(DropUnsupportedPieces(mesh, {WallView(0), WallView(0.5)}, SupportOptions{}, summary).triangles.size(), 8u);
  // With the column at x = 0 in front too, more of it lies in free space than on the wall.
  for (Eigen::Vector3f& v : mesh.vertices) {
    if (v.x() >= 0) v.z() = kWallDepth - 3;
  }
  EXPECT_EQ(DropUnsupportedPieces(mesh, {WallView(0), WallView(0.5)}, SupportOptions{}, summary).triangles.size(), 0u);
  EXPECT_EQ(summary.dropped_pieces, 1u);
}

TEST(Support, OptionsOutOfRangeAreRefused) {
  SupportOptions options;
  options.depth_tolerance = 0;
  EXPECT_THROW(options.Check(), UsageError);
  options = SupportOptions{};
  options.min_views = 0;
  EXPECT_THROW(options.Check(), UsageError);
}

}  // namespace
}  // namespace parallax

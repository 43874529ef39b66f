#include "geometry/simplify.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

// A UV sphere of radius `radius` with `rings` x `segments` quads (two triangles each).
TriangleMesh Sphere(double radius, int rings, int segments) {
  TriangleMesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * std::numbers::pi * s / segments;
      mesh.vertices.emplace_back(radius * std::sin(theta) * std::cos(phi), radius * std::sin(theta) * std::sin(phi),
                                 radius * std::cos(theta));
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments;
      const int c = a + segments, d = b + segments;
      mesh.triangles.emplace_back(a, c, b);
      mesh.triangles.emplace_back(b, c, d);
    }
  }
  return mesh;
}

// A flat grid of n x n quads in the plane z = height.
TriangleMesh FlatGrid(int n, float height) {
  TriangleMesh mesh;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) mesh.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), height);
  }
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int a = y * (n + 1) + x;
      mesh.triangles.emplace_back(a, a + 1, a + n + 1);
      mesh.triangles.emplace_back(a + 1, a + n + 2, a + n + 1);
    }
  }
  return mesh;
}

TEST(SimplifyMesh, SphereFitsTheBudgetCloselyAndStaysOnTheSurface) {
  const TriangleMesh sphere = Sphere(2.0, 100, 200);  // 40000 triangles.
  const TriangleMesh simplified = SimplifyMesh(sphere, 4000);
  EXPECT_LE(simplified.triangles.size(), 4000u);
  // The finest grid that fits: not far below the budget.
  EXPECT_GE(simplified.triangles.size(), 3000u);  // 3882 measured.
  double worst = 0;
  for (const Eigen::Vector3f& v : simplified.vertices) worst = std::max(worst, std::abs(static_cast<double>(v.norm()) - 2.0));
  // Cells are about 0.13 wide; the representatives stay within a small fraction of a cell of
  // the surface (0.0022 measured), never at a cell's corner.
  EXPECT_LT(worst, 0.01);
  for (const Eigen::Vector3i& t : simplified.triangles) {
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
  }
}

TEST(SimplifyMesh, FlatPatchStaysExactlyFlat) {
  // The quadric of a plane is singular along it: the representative must not wander off.
  const TriangleMesh simplified = SimplifyMesh(FlatGrid(100, 3.5f), 2000);
  ASSERT_GT(simplified.triangles.size(), 1000u);
  EXPECT_LE(simplified.triangles.size(), 2000u);
  for (const Eigen::Vector3f& v : simplified.vertices) {
    ASSERT_TRUE(v.allFinite());
    EXPECT_NEAR(v.z(), 3.5f, 1e-5f);
    EXPECT_GE(v.x(), -1e-5f);
    EXPECT_LE(v.x(), 100.00001f);
  }
}

TEST(SimplifyMesh, MeshWithinBudgetIsReturnedUnchangedAndBadInputIsRefused) {
  const TriangleMesh grid = FlatGrid(4, 0);
  const TriangleMesh same = SimplifyMesh(grid, grid.triangles.size());
  EXPECT_EQ(same.triangles, grid.triangles);
  EXPECT_EQ(same.vertices, grid.vertices);
  EXPECT_THROW(SimplifyMesh(grid, 0), InternalError);
  TriangleMesh broken = grid;
  broken.triangles.back()[2] = static_cast<int>(grid.vertices.size());
  EXPECT_THROW(SimplifyMesh(broken, 1), InternalError);
}

}  // namespace
}  // namespace parallax

// Marching cubes against what the surface must be: every one of the 256 cases closed around its
// inside corners, consistently turned, one sphere per group of corners; a sphere and a torus
// sampled from their signed distances, against their analytic surface, area, volume and genus.
#include "mesh/marching_cubes.h"

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

SampledField Sample(const Eigen::Vector3i& size, double spacing, const std::function<double(const Eigen::Vector3d&)>& f) {
  SampledField field;
  field.size = size;
  field.spacing = spacing;
  for (int z = 0; z < size.z(); ++z) {
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) field.values.push_back(static_cast<float>(f(spacing * Eigen::Vector3d(x, y, z))));
    }
  }
  return field;
}

struct SurfaceCheck {
  bool closed = true;      // Every edge in exactly two triangles, once each way.
  int euler = 0;           // V - E + F: 2 per sphere, 0 per torus.
  double area = 0;
  double volume = 0;       // Enclosed, positive when the triangles face outwards.
};

SurfaceCheck Check(const TriangleMesh& mesh) {
  SurfaceCheck check;
  std::map<std::pair<int, int>, int> directed;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    check.area += 0.5 * (b - a).cross(c - a).norm();
    check.volume += a.dot(b.cross(c)) / 6;
  }
  size_t edges = 0;
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) check.closed = false;
    if (edge.first < edge.second) ++edges;
  }
  check.euler = static_cast<int>(mesh.vertices.size()) - static_cast<int>(edges) + static_cast<int>(mesh.triangles.size());
  return check;
}

// Groups of the mask's inside corners joined along the cube's edges.
int InsideGroups(int mask) {
  int groups = 0, seen = 0;
  for (int start = 0; start < 8; ++start) {
    if (!((mask >> start) & 1) || ((seen >> start) & 1)) continue;
    ++groups;
    std::vector<int> stack = {start};
    seen |= 1 << start;
    while (!stack.empty()) {
      const int corner = stack.back();
      stack.pop_back();
      for (int axis = 0; axis < 3; ++axis) {
        const int neighbour = corner ^ (1 << axis);
        if (((mask >> neighbour) & 1) && !((seen >> neighbour) & 1)) {
          seen |= 1 << neighbour;
          stack.push_back(neighbour);
        }
      }
    }
  }
  return groups;
}

// Each case as the middle cell of a 4x4x4 field that is positive everywhere else: the surface
// closes around the inside corners, its triangles face out, each group of corners joined along
// an edge is one sphere (Euler characteristic 2), and every vertex is halfway along its edge.
TEST(MarchingCubes, EveryCaseClosesAroundItsInsideCorners) {
  const std::array<MarchingCubesCase, 256>& table = MarchingCubesTable();
  EXPECT_TRUE(table[0].triangles.empty());
  EXPECT_TRUE(table[255].triangles.empty());
  for (int mask = 1; mask < 256; ++mask) {
    EXPECT_LE(table[mask].triangles.size(), 5u) << mask;
    SampledField field;
    field.size = Eigen::Vector3i(4, 4, 4);
    field.values.assign(64, 1.0f);
    for (int corner = 0; corner < 8; ++corner) {
      const int x = 1 + (corner & 1), y = 1 + ((corner >> 1) & 1), z = 1 + ((corner >> 2) & 1);
      if ((mask >> corner) & 1) field.values[(z * 4 + y) * 4 + x] = -1;
    }
    const TriangleMesh mesh = MarchingCubes(field);
    const SurfaceCheck check = Check(mesh);
    EXPECT_TRUE(check.closed) << "case " << mask;
    EXPECT_GT(check.volume, 0) << "case " << mask;
    EXPECT_EQ(check.euler, 2 * InsideGroups(mask)) << "case " << mask;
    for (const Eigen::Vector3f& v : mesh.vertices) {
      // Between samples of -1 and +1 the crossing is halfway: one coordinate ends in .5.
      const Eigen::Vector3f fraction = v - v.array().floor().matrix();
      EXPECT_EQ((fraction.array() == 0.5f).count(), 1) << "case " << mask;
    }
  }
}

// A sphere of radius 10 samples, off the grid's axes: vertices within 0.02 samples of the
// analytic sphere, area and volume within 1%, one closed sphere.
TEST(MarchingCubes, SphereLiesOnTheAnalyticSurface) {
  const double spacing = 0.1, radius = 1.0;
  const Eigen::Vector3d centre(1.23, 1.31, 1.17);
  const SampledField field = Sample(Eigen::Vector3i(26, 27, 25), spacing,
                                    [&](const Eigen::Vector3d& p) { return (p - centre).norm() - radius; });
  const TriangleMesh mesh = MarchingCubes(field);
  double worst = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) worst = std::max(worst, std::abs((v.cast<double>() - centre).norm() - radius));
  const SurfaceCheck check = Check(mesh);
  const double area = 4 * std::numbers::pi * radius * radius, volume = 4 * std::numbers::pi * std::pow(radius, 3) / 3;
  std::printf("[ measure ] sphere: %zu triangles, vertices up to %.4f samples off, area %+.3f%%, volume %+.3f%%\n",
              mesh.triangles.size(), worst / spacing, 100 * (check.area / area - 1), 100 * (check.volume / volume - 1));
  EXPECT_TRUE(check.closed);
  EXPECT_EQ(check.euler, 2);
  EXPECT_LT(worst, 0.02 * spacing);
  EXPECT_NEAR(check.area, area, 0.01 * area);
  EXPECT_NEAR(check.volume, volume, 0.01 * volume);
}

// A torus (genus 1: Euler characteristic 0), tube radius 4 samples, ring 10.
TEST(MarchingCubes, TorusHasOneHole) {
  const double spacing = 0.1, ring = 1.0, tube = 0.4;
  const Eigen::Vector3d centre(1.52, 1.47, 0.61);
  const SampledField field = Sample(Eigen::Vector3i(31, 31, 13), spacing, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = p - centre;
    return std::hypot(std::hypot(q.x(), q.y()) - ring, q.z()) - tube;
  });
  const TriangleMesh mesh = MarchingCubes(field);
  const SurfaceCheck check = Check(mesh);
  const double volume = 2 * std::numbers::pi * std::numbers::pi * ring * tube * tube;
  std::printf("[ measure ] torus: %zu triangles, volume %+.3f%%\n", mesh.triangles.size(),
              100 * (check.volume / volume - 1));
  EXPECT_TRUE(check.closed);
  EXPECT_EQ(check.euler, 0);
  EXPECT_NEAR(check.volume, volume, 0.02 * volume);
}

// Where a sample is unknown no cell touching it makes triangles: the sphere cut open where the
// field is NaN, never closed across it.
TEST(MarchingCubes, UnknownSamplesMakeNoSurfaceAndBadGridsAreRefused) {
  const Eigen::Vector3d centre(1.2, 1.2, 1.2);
  SampledField field = Sample(Eigen::Vector3i(25, 25, 25), 0.1,
                              [&](const Eigen::Vector3d& p) { return (p - centre).norm() - 1.0; });
  const size_t whole = MarchingCubes(field).triangles.size();
  for (int z = 0; z < 25; ++z) {
    for (int y = 0; y < 25; ++y) {
      for (int x = 13; x < 25; ++x) field.values[(z * 25 + y) * 25 + x] = std::numeric_limits<float>::quiet_NaN();
    }
  }
  const TriangleMesh half = MarchingCubes(field);
  for (const Eigen::Vector3f& v : half.vertices) EXPECT_LE(v.x(), 1.2f + 1e-5f);
  EXPECT_FALSE(Check(half).closed);
  EXPECT_GT(half.triangles.size(), whole / 3);
  EXPECT_LT(half.triangles.size(), 2 * whole / 3);

  IsoSurfaceMesher mesher;
  mesher.Add(field);
  SampledField other_grid = field;
  other_grid.origin.x() += 0.05;
  EXPECT_THROW(mesher.Add(other_grid), BadInputError);
  field.values.pop_back();
  EXPECT_THROW(MarchingCubes(field), BadInputError);
  field.values.push_back(1);
  field.spacing = 0;
  EXPECT_THROW(MarchingCubes(field), BadInputError);
}

}  // namespace
}  // namespace parallax

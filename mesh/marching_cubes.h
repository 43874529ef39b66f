#pragma once
// The zero iso-surface of a sampled field by marching cubes (Lorensen and Cline 1987; the seed's
// volume chapter): the signs of a cell's 8 corner samples pick one of 256 cases, and the case's
// triangles join points on the cell's edges where the field crosses zero, placed by linear
// interpolation along the edge. The case table is built here from the cube's faces: on each
// face the surface crosses the edges between corners of opposite sign, one segment per run of
// negative (inside) corners, so a face with two diagonal inside corners keeps them apart and two
// cells sharing that face cut it alike; the segments chain into closed loops, each fanned into
// triangles. Points on a shared edge are one vertex, so the surface is closed wherever every
// sample around it is known; its triangles face the positive side.
#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace parallax {

// A scalar field sampled at the corners of a regular grid, or at a box of them: negative inside,
// positive outside, NaN where it is unknown (a cell with an unknown corner makes no triangles).
struct SampledField {
  Eigen::Vector3i size = Eigen::Vector3i::Zero();   // Samples along x, y, z.
  Eigen::Vector3i first = Eigen::Vector3i::Zero();  // The grid index of this box's first sample.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // The position of the grid's sample (0, 0, 0).
  double spacing = 1;                               // Between neighbouring samples.
  std::vector<float> values;                        // x fastest, then y, then z.

  float At(int x, int y, int z) const {
    return values[(static_cast<size_t>(z) * size.y() + y) * size.x() + x];
  }
};

// One case of the table: triangles as triples of cube edges (0-11), at most 5 of them.
struct MarchingCubesCase {
  std::vector<std::array<int, 3>> triangles;
};

// The 256 cases, by the bit mask of the corners that are inside (corner i = bit i at
// (i & 1, (i >> 1) & 1, (i >> 2) & 1)).
const std::array<MarchingCubesCase, 256>& MarchingCubesTable();

// The zero iso-surface of boxes of one grid (the same origin and spacing), added one by one:
// cells of different boxes that share a grid edge share its vertex, so the boxes join without
// seams (a cell belongs to the box holding all eight of its corners).
class IsoSurfaceMesher {
 public:
  // Throws BadInputError when `values` does not hold size.prod() samples, the spacing is not
  // positive, the grid differs from the boxes' before, or an index is beyond 2^19 samples.
  void Add(const SampledField& field);
  TriangleMesh Take() { return std::move(mesh_); }

 private:
  TriangleMesh mesh_;
  std::unordered_map<uint64_t, int> vertex_of_edge_;  // A grid edge: its lower sample and axis.
  std::optional<std::pair<Eigen::Vector3d, double>> grid_;  // Origin and spacing.
};

// The zero iso-surface of one field.
TriangleMesh MarchingCubes(const SampledField& field);

}  // namespace parallax

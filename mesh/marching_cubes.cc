#include "mesh/marching_cubes.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "core/error.h"

namespace parallax {
namespace {

// Corner i of a cell sits at (i & 1, (i >> 1) & 1, (i >> 2) & 1); edges along x, then y, then z.
constexpr std::array<std::array<int, 2>, 12> kEdgeCorners = {{{0, 1}, {2, 3}, {4, 5}, {6, 7},
                                                               {0, 2}, {1, 3}, {4, 6}, {5, 7},
                                                               {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

// Each face's corners counter-clockwise seen from outside the cell (around its outward normal):
// x = 0, x = 1, y = 0, y = 1, z = 0, z = 1.
constexpr std::array<std::array<int, 4>, 6> kFaceCorners = {
    {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};

int EdgeBetween(int a, int b) {
  for (int edge = 0; edge < 12; ++edge) {
    const auto [c0, c1] = kEdgeCorners[edge];
    if ((c0 == a && c1 == b) || (c0 == b && c1 == a)) return edge;
  }
  throw InternalError("marching cubes: corners " + std::to_string(a) + " and " + std::to_string(b) +
                      " share no edge");
}

// The triangles of the case whose inside corners are the bits of `mask`. On each face, walking
// its corners counter-clockwise from outside, a run of inside corners is entered across one
// edge and left across another; the segment from the first to the second, over all faces,
// makes closed loops (every crossed edge is left on one of its faces and entered on the other)
// that turn counter-clockwise around the direction from inside to outside.
MarchingCubesCase BuildCase(int mask) {
  const auto inside = [mask](int corner) { return (mask >> corner) & 1; };
  std::array<int, 12> next;
  next.fill(-1);
  for (const std::array<int, 4>& face : kFaceCorners) {
    for (int k = 0; k < 4; ++k) {
      if (inside(face[k]) || !inside(face[(k + 1) % 4])) continue;  // Not where a run starts.
      int last = (k + 1) % 4;
      while (inside(face[(last + 1) % 4])) last = (last + 1) % 4;
      next[EdgeBetween(face[k], face[(k + 1) % 4])] = EdgeBetween(face[last], face[(last + 1) % 4]);
    }
  }
  MarchingCubesCase result;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (next[start] < 0 || used[start]) continue;
    std::vector<int> loop;
    for (int edge = start; !used[edge]; edge = next[edge]) {
      if (next[edge] < 0) throw InternalError("marching cubes: case " + std::to_string(mask) + " leaves a loop open");
      used[edge] = true;
      loop.push_back(edge);
    }
    for (size_t i = 1; i + 1 < loop.size(); ++i) result.triangles.push_back({loop[0], loop[i], loop[i + 1]});
  }
  return result;
}

}  // namespace

const std::array<MarchingCubesCase, 256>& MarchingCubesTable() {
  static const std::array<MarchingCubesCase, 256> table = [] {
    std::array<MarchingCubesCase, 256> cases;
    for (int mask = 0; mask < 256; ++mask) cases[mask] = BuildCase(mask);
    return cases;
  }();
  return table;
}

void IsoSurfaceMesher::Add(const SampledField& field) {
  const Eigen::Vector3i& n = field.size;
  if ((n.array() < 0).any() || field.values.size() != static_cast<size_t>(n.x()) * n.y() * n.z()) {
    throw BadInputError("marching cubes: " + std::to_string(field.values.size()) + " samples for a box of " +
                        std::to_string(n.x()) + " x " + std::to_string(n.y()) + " x " + std::to_string(n.z()));
  }
  if (!(field.spacing > 0)) throw BadInputError("marching cubes: the spacing must be positive");
  if (!grid_) grid_.emplace(field.origin, field.spacing);
  if (grid_->first != field.origin || grid_->second != field.spacing) {
    throw BadInputError("marching cubes: boxes of different grids");
  }
  constexpr int kIndexLimit = 1 << 19;
  const Eigen::Vector3i last = field.first + n;
  if ((field.first.array() < -kIndexLimit).any() || (last.array() > kIndexLimit).any()) {
    throw BadInputError("marching cubes: a sample index beyond 2^19");
  }
  const std::array<MarchingCubesCase, 256>& table = MarchingCubesTable();
  const auto vertex = [&](const Eigen::Vector3i& cell, int edge, const std::array<float, 8>& values) {
    const auto [a, b] = kEdgeCorners[edge];
    const Eigen::Vector3i pa = field.first + cell + Eigen::Vector3i(a & 1, (a >> 1) & 1, (a >> 2) & 1);
    const Eigen::Vector3i pb = field.first + cell + Eigen::Vector3i(b & 1, (b >> 1) & 1, (b >> 2) & 1);
    const Eigen::Array<uint64_t, 3, 1> biased = (pa.array() + kIndexLimit).cast<uint64_t>();
    const uint64_t key = (((biased.z() << 20 | biased.y()) << 20 | biased.x()) << 2) | static_cast<uint64_t>(edge / 4);
    const auto [found, inserted] = vertex_of_edge_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (inserted) {
      // The signs differ, so the denominator is not zero; t in [0, 1].
      const double value_a = values[a], value_b = values[b];
      const double t = value_a / (value_a - value_b);
      const Eigen::Vector3d position =
          field.origin + field.spacing * (pa.cast<double>() + t * (pb - pa).cast<double>());
      mesh_.vertices.push_back(position.cast<float>());
    }
    return found->second;
  };
  for (int z = 0; z + 1 < n.z(); ++z) {
    for (int y = 0; y + 1 < n.y(); ++y) {
      for (int x = 0; x + 1 < n.x(); ++x) {
        std::array<float, 8> values;
        int mask = 0;
        bool known = true;
        for (int corner = 0; corner < 8; ++corner) {
          values[corner] = field.At(x + (corner & 1), y + ((corner >> 1) & 1), z + ((corner >> 2) & 1));
          known = known && std::isfinite(values[corner]);
          if (values[corner] < 0) mask |= 1 << corner;
        }
        if (!known || mask == 0 || mask == 255) continue;
        const Eigen::Vector3i cell(x, y, z);
        for (const std::array<int, 3>& triangle : table[mask].triangles) {
          mesh_.triangles.emplace_back(vertex(cell, triangle[0], values), vertex(cell, triangle[1], values),
                                       vertex(cell, triangle[2], values));
        }
      }
    }
  }
}

TriangleMesh MarchingCubes(const SampledField& field) {
  IsoSurfaceMesher mesher;
  mesher.Add(field);
  return mesher.Take();
}

}  // namespace parallax

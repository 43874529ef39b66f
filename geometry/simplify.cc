#include "geometry/simplify.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/hash.h"

namespace parallax {
namespace {

// A uniform grid over the mesh's bounding box; cells are packed into 21 bits per axis.
class ClusterGrid {
 public:
  ClusterGrid(const Eigen::AlignedBox3d& box, double cell) : origin_(box.min()), cell_(cell) {}

  uint64_t Key(const Eigen::Vector3f& p) const {
    const Eigen::Vector3d c = ((p.cast<double>() - origin_) / cell_).array().floor();
    return (static_cast<uint64_t>(c.x()) << 42) | (static_cast<uint64_t>(c.y()) << 21) |
           static_cast<uint64_t>(c.z());
  }
  Eigen::AlignedBox3d Box(uint64_t key) const {
    const Eigen::Vector3d low = origin_ + cell_ * Eigen::Vector3d(static_cast<double>(key >> 42),
                                                                  static_cast<double>((key >> 21) & 0x1FFFFF),
                                                                  static_cast<double>(key & 0x1FFFFF));
    return {low, low + Eigen::Vector3d::Constant(cell_)};
  }
  double Cell() const { return cell_; }

 private:
  Eigen::Vector3d origin_;
  double cell_;
};

struct KeyHash {
  size_t operator()(uint64_t key) const { return static_cast<size_t>(MixBits(key)); }
};

// The triangles that survive clustering, as cell-key triples, each once (whatever the corner
// order; the first triangle's orientation is kept).
std::vector<std::array<uint64_t, 3>> ClusteredTriangles(const TriangleMesh& mesh, const ClusterGrid& grid) {
  std::vector<uint64_t> keys(mesh.vertices.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) keys[v] = grid.Key(mesh.vertices[v]);
  std::vector<std::array<uint64_t, 3>> triangles;
  std::unordered_set<uint64_t> seen;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const std::array<uint64_t, 3> cells = {keys[static_cast<size_t>(t[0])], keys[static_cast<size_t>(t[1])],
                                           keys[static_cast<size_t>(t[2])]};
    if (cells[0] == cells[1] || cells[1] == cells[2] || cells[0] == cells[2]) continue;
    std::array<uint64_t, 3> sorted = cells;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(MixBits(sorted[0] ^ MixBits(sorted[1] ^ MixBits(sorted[2])))).second) continue;
    triangles.push_back(cells);
  }
  return triangles;
}

// The sum of the squared distances to the planes of a cell's triangles (area-weighted), and
// the mean of its vertices.
struct CellQuadric {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_sum = Eigen::Vector3d::Zero();
  int count = 0;

  // The point minimising the quadric, found from the vertices' mean along the directions the
  // planes constrain only: on a flat patch the quadric says nothing about sliding within the
  // plane, and a plain inverse would be singular there. Kept inside the cell.
  Eigen::Vector3d Representative(const Eigen::AlignedBox3d& cell) const {
    const Eigen::Vector3d mean = position_sum / count;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
    const Eigen::Vector3d residual = -b - a * mean;
    const double largest = solver.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      const double lambda = solver.eigenvalues()[i];
      if (lambda > 1e-3 * largest && lambda > 0) {
        const Eigen::Vector3d axis = solver.eigenvectors().col(i);
        step += axis * (axis.dot(residual) / lambda);
      }
    }
    const Eigen::Vector3d point = mean + step;
    return point.allFinite() ? point.cwiseMax(cell.min()).cwiseMin(cell.max()) : mean;
  }
};

TriangleMesh Cluster(const TriangleMesh& mesh, const ClusterGrid& grid) {
  std::unordered_map<uint64_t, CellQuadric, KeyHash> quadrics;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    CellQuadric& q = quadrics[grid.Key(v)];
    q.position_sum += v.cast<double>();
    ++q.count;
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d p0 = mesh.vertices[static_cast<size_t>(t[0])].cast<double>();
    const Eigen::Vector3d cross = (mesh.vertices[static_cast<size_t>(t[1])].cast<double>() - p0)
                                      .cross(mesh.vertices[static_cast<size_t>(t[2])].cast<double>() - p0);
    const double norm = cross.norm();
    if (!(norm > 0)) continue;
    const Eigen::Vector3d normal = cross / norm;
    const double area = 0.5 * norm, offset = -normal.dot(p0);
    for (int c = 0; c < 3; ++c) {
      CellQuadric& q = quadrics[grid.Key(mesh.vertices[static_cast<size_t>(t[c])])];
      q.a += area * normal * normal.transpose();
      q.b += area * offset * normal;
    }
  }
  TriangleMesh simplified;
  std::unordered_map<uint64_t, int, KeyHash> index;
  for (const std::array<uint64_t, 3>& cells : ClusteredTriangles(mesh, grid)) {
    Eigen::Vector3i triangle;
    for (int c = 0; c < 3; ++c) {
      const auto [found, inserted] = index.try_emplace(cells[c], static_cast<int>(simplified.vertices.size()));
      if (inserted) {
        simplified.vertices.push_back(quadrics.at(cells[c]).Representative(grid.Box(cells[c])).cast<float>());
      }
      triangle[c] = found->second;
    }
    simplified.triangles.push_back(triangle);
  }
  return simplified;
}

}  // namespace

TriangleMesh SimplifyMesh(const TriangleMesh& mesh, size_t max_triangles) {
  if (max_triangles < 1) throw InternalError("SimplifyMesh: the budget must be at least 1 triangle");
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (t.minCoeff() < 0 || static_cast<size_t>(t.maxCoeff()) >= mesh.vertices.size()) {
      throw InternalError("SimplifyMesh: a triangle indexes outside the vertices");
    }
  }
  if (mesh.triangles.size() <= max_triangles) return mesh;
  Eigen::AlignedBox3d box;
  double area = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v.cast<double>());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f& p0 = mesh.vertices[static_cast<size_t>(t[0])];
    area += 0.5 * static_cast<double>((mesh.vertices[static_cast<size_t>(t[1])] - p0)
                                          .cross(mesh.vertices[static_cast<size_t>(t[2])] - p0)
                                          .norm());
  }
  // A surface clustered into cells of side s keeps about 2 area / s^2 triangles. Bisect the
  // cell size (in log space) between one that surely fits and one that surely does not; the
  // finest that fits wins. The finest cell keeps grid coordinates within 21 bits.
  const double extent = std::max(box.diagonal().maxCoeff(), 1e-30);
  double fits = extent, too_fine = std::max(std::sqrt(area / static_cast<double>(max_triangles)), extent / (1 << 20));
  for (int iteration = 0; iteration < 12 && fits / too_fine > 1.02; ++iteration) {
    const double cell = std::sqrt(fits * too_fine);
    const size_t count = ClusteredTriangles(mesh, ClusterGrid(box, cell)).size();
    (count <= max_triangles ? fits : too_fine) = cell;
  }
  return Cluster(mesh, ClusterGrid(box, fits));
}

}  // namespace parallax

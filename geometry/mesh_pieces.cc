#include "geometry/mesh_pieces.h"

#include <numeric>

#include "core/error.h"

namespace parallax {
namespace {

int Root(std::vector<int>& parent, int v) {
  while (parent[static_cast<size_t>(v)] != v) {
    int& up = parent[static_cast<size_t>(v)];
    up = parent[static_cast<size_t>(up)];  // Path halving keeps the trees flat.
    v = up;
  }
  return v;
}

}  // namespace

std::vector<int> PieceOfEachVertex(const TriangleMesh& mesh, int& piece_count) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    const int a = Root(parent, triangle[0]);
    for (int c = 1; c < 3; ++c) {
      const int b = Root(parent, triangle[c]);
      parent[static_cast<size_t>(b)] = Root(parent, a);
    }
  }
  std::vector<int> piece_of_root(mesh.vertices.size(), -1);
  std::vector<int> piece(mesh.vertices.size());
  piece_count = 0;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    int& number = piece_of_root[static_cast<size_t>(Root(parent, static_cast<int>(v)))];
    if (number < 0) number = piece_count++;
    piece[v] = number;
  }
  return piece;
}

TriangleMesh KeepTriangles(const TriangleMesh& mesh, const std::vector<uint8_t>& keep) {
  if (keep.size() != mesh.triangles.size()) {
    throw InternalError("KeepTriangles: one entry per triangle expected");
  }
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const bool colors = mesh.colors.size() == mesh.vertices.size();
  TriangleMesh kept;
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!keep[t]) continue;
    Eigen::Vector3i renumbered;
    for (int c = 0; c < 3; ++c) {
      const auto old_index = static_cast<size_t>(mesh.triangles[t][c]);
      int& index = new_index[old_index];
      if (index < 0) {
        index = static_cast<int>(kept.vertices.size());
        kept.vertices.push_back(mesh.vertices[old_index]);
        if (normals) kept.normals.push_back(mesh.normals[old_index]);
        if (colors) kept.colors.push_back(mesh.colors[old_index]);
      }
      renumbered[c] = index;
    }
    kept.triangles.push_back(renumbered);
  }
  return kept;
}

}  // namespace parallax

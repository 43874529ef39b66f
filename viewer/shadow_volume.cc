#include "viewer/shadow_volume.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <unordered_map>
#include <utility>

#include <Eigen/Geometry>

namespace parallax {
namespace {

// Where each vertex is seen from the light: moved away from it, and its image at infinity.
struct LitVertices {
  std::vector<Eigen::Vector4f> moved;
  std::vector<Eigen::Vector4f> at_infinity;
  std::vector<bool> valid;  // False at a point light's own position.
};

LitVertices SeeFromLight(const TriangleMesh& mesh, const Eigen::Vector4d& light, float offset) {
  LitVertices lit;
  const size_t n = mesh.vertices.size();
  lit.moved.resize(n);
  lit.at_infinity.resize(n);
  lit.valid.assign(n, true);
  const bool point = light.w() != 0;
  const Eigen::Vector3d towards_sun = light.head<3>().normalized();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = mesh.vertices[i].cast<double>();
    Eigen::Vector3d towards = towards_sun;
    if (point) {
      towards = light.head<3>() - x;
      const double distance = towards.norm();
      if (!(distance > 0)) {
        lit.valid[i] = false;
        continue;
      }
      towards /= distance;
    }
    const Eigen::Vector3d moved = x - offset * towards;
    lit.moved[i] = Eigen::Vector4d(moved.x(), moved.y(), moved.z(), 1).cast<float>();
    lit.at_infinity[i] = Eigen::Vector4d(-towards.x(), -towards.y(), -towards.z(), 0).cast<float>();
  }
  return lit;
}

uint64_t EdgeKey(int a, int b) {
  return (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
}

}  // namespace

ShadowVolume BuildShadowVolume(const TriangleMesh& mesh, const Eigen::Vector4d& light, float offset) {
  const LitVertices lit = SeeFromLight(mesh, light, offset);
  const bool point = light.w() != 0;
  ShadowVolume volume;
  auto add = [&volume](const Eigen::Vector4f& a, const Eigen::Vector4f& b, const Eigen::Vector4f& c) {
    volume.vertices.insert(volume.vertices.end(), {a, b, c});
  };
  // Per edge, +1 for each caster turned to face the light that runs along it from its lower
  // vertex index to its higher, -1 for each that runs the other way.
  std::unordered_map<uint64_t, int> edge_turns;
  edge_turns.reserve(mesh.triangles.size() * 2);
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    int a = triangle[0], b = triangle[1], c = triangle[2];
    if (!lit.valid[a] || !lit.valid[b] || !lit.valid[c]) continue;
    const Eigen::Vector3d pa = mesh.vertices[a].cast<double>(), pb = mesh.vertices[b].cast<double>(),
                          pc = mesh.vertices[c].cast<double>();
    const Eigen::Vector3d normal = (pb - pa).cross(pc - pa);
    const Eigen::Vector3d towards =
        point ? Eigen::Vector3d(light.head<3>() - (pa + pb + pc) / 3) : Eigen::Vector3d(light.head<3>());
    const double facing = normal.dot(towards.normalized());
    if (!(std::abs(facing) > 1e-12 * normal.norm())) continue;  // Edge-on, degenerate or not finite.
    if (facing < 0) std::swap(b, c);
    add(lit.moved[a], lit.moved[b], lit.moved[c]);
    ++volume.caps;
    if (point) {
      add(lit.at_infinity[a], lit.at_infinity[c], lit.at_infinity[b]);
      ++volume.caps;
    }
    for (const auto& [from, to] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      edge_turns[EdgeKey(from, to)] += from < to ? 1 : -1;
    }
  }
  for (const auto& [key, turns] : edge_turns) {
    if (turns == 0) continue;
    const int low = static_cast<int>(key >> 32), high = static_cast<int>(key & 0xffffffffu);
    // The edge as the casters facing the light run along it; its extrusion faces away from them.
    const int p = turns > 0 ? low : high, q = turns > 0 ? high : low;
    for (int copy = 0; copy < std::abs(turns); ++copy) {
      ++volume.silhouette_edges;
      add(lit.moved[q], lit.moved[p], lit.at_infinity[p]);
      if (point) add(lit.moved[q], lit.at_infinity[p], lit.at_infinity[q]);
    }
  }
  return volume;
}

}  // namespace parallax

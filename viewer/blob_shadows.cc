#include "viewer/blob_shadows.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace parallax {
namespace {

int Root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Where a point lands on the ground when pushed along the light; none when the light does not
// come from above it.
std::optional<Eigen::Vector3d> OntoGround(const Eigen::Vector3d& x, const GroundPlane& ground,
                                          const Eigen::Vector4d& light) {
  const double height = ground.SignedDistance(x);
  if (light.w() == 0) {
    const Eigen::Vector3d towards = light.head<3>().normalized();
    const double rise = ground.normal.dot(towards);  // Height gained per unit towards the light.
    if (!(rise > 1e-3)) return std::nullopt;
    return x - (height / rise) * towards;
  }
  const Eigen::Vector3d lamp = light.head<3>();
  const double lamp_height = ground.SignedDistance(lamp);
  if (!(lamp_height > height) || !(lamp_height > 0)) return std::nullopt;
  return lamp + (x - lamp) * (lamp_height / (lamp_height - height));
}

// The ellipse holding about 95% of `points` on the ground: two standard deviations along each
// principal axis of their spread, at least `min_radius`.
Blob SpreadOnGround(const std::vector<Eigen::Vector3d>& points, const GroundPlane& ground, double min_radius) {
  const Eigen::Vector3d e1 = ground.normal.unitOrthogonal(), e2 = ground.normal.cross(e1);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d q((p - mean).dot(e1), (p - mean).dot(e2));
    spread += q * q.transpose();
  }
  spread /= static_cast<double>(points.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(spread);
  Blob blob;
  blob.centre = (mean - ground.SignedDistance(mean) * ground.normal).cast<float>();
  Eigen::Vector3f* const out[2] = {&blob.axis_u, &blob.axis_v};
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d along = axes.eigenvectors().col(k);
    const double radius = std::max(2 * std::sqrt(std::max(axes.eigenvalues()[k], 0.0)), min_radius);
    *out[k] = (radius * (along.x() * e1 + along.y() * e2)).cast<float>();
  }
  return blob;
}

}  // namespace

BlobCasters FindBlobCasters(const TriangleMesh& mesh, const GroundPlane& ground, float tolerance, float max_radius,
                            int max_objects, double min_share) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<bool> above(mesh.vertices.size(), false);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    bool standing = false;
    for (int c = 0; c < 3; ++c) {
      standing |= ground.SignedDistance(mesh.vertices[t[c]].cast<double>()) > static_cast<double>(tolerance);
    }
    if (!standing) continue;
    for (int c = 0; c < 3; ++c) above[t[c]] = true;
    parent[Root(parent, t[1])] = Root(parent, t[0]);
    parent[Root(parent, t[2])] = Root(parent, t[0]);
  }
  std::vector<std::vector<int>> by_root(mesh.vertices.size());
  size_t total = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!above[i]) continue;
    by_root[Root(parent, static_cast<int>(i))].push_back(static_cast<int>(i));
    ++total;
  }
  BlobCasters casters;
  for (std::vector<int>& object : by_root) {
    if (object.empty() || static_cast<double>(object.size()) < min_share * static_cast<double>(total)) continue;
    std::vector<Eigen::Vector3d> points;
    for (int i : object) points.push_back(mesh.vertices[i].cast<double>());
    const Blob footprint = SpreadOnGround(points, ground, 0);
    if (std::max(footprint.axis_u.norm(), footprint.axis_v.norm()) <= max_radius) {
      casters.objects.push_back(std::move(object));
    }
  }
  std::sort(casters.objects.begin(), casters.objects.end(),
            [](const auto& a, const auto& b) { return a.size() > b.size(); });
  if (static_cast<int>(casters.objects.size()) > max_objects) casters.objects.resize(static_cast<size_t>(max_objects));
  return casters;
}

std::vector<Blob> PlaceBlobs(const TriangleMesh& mesh, const BlobCasters& casters, const GroundPlane& ground,
                             const Eigen::Vector4d& light, float min_radius) {
  std::vector<Blob> blobs;
  for (const std::vector<int>& object : casters.objects) {
    std::vector<Eigen::Vector3d> landed;
    for (int i : object) {
      if (const auto point = OntoGround(mesh.vertices[i].cast<double>(), ground, light)) landed.push_back(*point);
    }
    if (landed.size() < 3) continue;
    const Blob blob = SpreadOnGround(landed, ground, min_radius);
    if (blob.centre.allFinite() && blob.axis_u.allFinite() && blob.axis_v.allFinite()) blobs.push_back(blob);
  }
  return blobs;
}

std::vector<float> BlobTexture(int size) {
  std::vector<float> texels(static_cast<size_t>(size) * static_cast<size_t>(size));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double s = 2 * (x + 0.5) / size - 1, t = 2 * (y + 0.5) / size - 1;
      const double r = std::clamp((std::hypot(s, t) - 2.0 / 3) * 3, 0.0, 1.0);
      // A shadow keeps the ambient light: about a third of the lit color in the core, then a
      // smoothstep from 2/3 to 1 of the radius.
      constexpr double kCore = 0.35;
      const double visibility = kCore + (1 - kCore) * r * r * (3 - 2 * r);
      texels[static_cast<size_t>(y) * static_cast<size_t>(size) + static_cast<size_t>(x)] =
          static_cast<float>(visibility);
    }
  }
  return texels;
}

}  // namespace parallax

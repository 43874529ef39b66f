#include "viewer/viewer_scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Dense>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "geometry/ply.h"
#include "geometry/robust_bounds.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Mean "up" (-y) of the source cameras in world coordinates; nullopt without cameras or when
// they disagree so much that the mean is meaningless.
std::optional<Eigen::Vector3d> CamerasUp(const std::vector<ViewerSource>& sources) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const ViewerSource& source : sources) {
    sum += source.cam_from_world.rotation.conjugate() * Eigen::Vector3d(0, -1, 0);
  }
  if (sources.empty() || sum.norm() < 0.3 * static_cast<double>(sources.size())) {
    return std::nullopt;
  }
  return sum.normalized();
}

// Points spread over the mesh by area (deterministic), so a large ground made of two
// triangles weighs as much as it covers.
std::vector<Eigen::Vector3f> SampleMesh(const TriangleMesh& mesh, int count) {
  std::vector<double> cumulative;
  double total = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[t[0]];
    total += 0.5 * static_cast<double>((mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm());
    cumulative.push_back(total);
  }
  std::vector<Eigen::Vector3f> samples;
  if (!(total > 0)) return samples;
  std::mt19937 random(1);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (int i = 0; i < count; ++i) {
    const size_t index = static_cast<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), uniform(random) * total) -
        cumulative.begin());
    const Eigen::Vector3i& t = mesh.triangles[std::min(index, mesh.triangles.size() - 1)];
    double u = uniform(random), v = uniform(random);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    samples.push_back(mesh.vertices[t[0]] +
                      static_cast<float>(u) * (mesh.vertices[t[1]] - mesh.vertices[t[0]]) +
                      static_cast<float>(v) * (mesh.vertices[t[2]] - mesh.vertices[t[0]]));
  }
  return samples;
}

// Robust bounds of the samples off the ground plus their footprints on it; empty when
// (nearly) everything is ground.
Eigen::AlignedBox3f FocusBounds(const std::vector<Eigen::Vector3f>& samples,
                                const std::optional<GroundPlane>& ground, float tolerance) {
  if (!ground) return {};
  std::vector<Eigen::Vector3f> standing;
  for (const Eigen::Vector3f& p : samples) {
    const double height = ground->SignedDistance(p.cast<double>());
    if (std::abs(height) <= static_cast<double>(tolerance)) continue;
    standing.push_back(p);
    standing.push_back((p.cast<double>() - height * ground->normal).cast<float>());
  }
  if (standing.size() < 20) return {};  // Too little off the ground to frame.
  return RobustBounds(standing);
}

// Every k-th point, at most about `count` of them (deterministic): robust statistics and the
// ground fit need no million points.
std::vector<Eigen::Vector3f> Subsample(const std::vector<ColoredPoint>& points, size_t count) {
  const size_t stride = std::max<size_t>(1, (points.size() + count - 1) / count);
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(points.size() / stride + 1);
  for (size_t i = 0; i < points.size(); i += stride) positions.push_back(points[i].position);
  return positions;
}

std::vector<ViewerSource> ReadSources(const fs::path& sparse_dir, const fs::path& images_dir,
                                      const ColorGains& gains) {
  std::vector<ViewerSource> sources;
  const SparseModel model = ReadSparseModel(sparse_dir);
  for (const SparseImage& image : model.Images()) {
    const Camera& camera = model.CameraById(image.camera_id);
    if (!IsProjectionSupported(camera.model)) continue;
    sources.push_back({image.name, camera, image.cam_from_world, images_dir / image.name, gains.Of(image.name)});
  }
  return sources;
}

}  // namespace

std::vector<ColoredPoint> ReadColoredPly(const fs::path& path) {
  const TriangleMesh cloud = ReadPly(path);
  std::vector<ColoredPoint> points(cloud.vertices.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].position = cloud.vertices[i];
    points[i].normal = cloud.normals.empty() ? Eigen::Vector3f::Zero() : cloud.normals[i];
    points[i].color = cloud.colors.empty() ? std::array<uint8_t, 3>{180, 180, 180} : cloud.colors[i];
    if (!points[i].normal.allFinite()) {
      throw BadInputError(path.string() + ": vertex " + std::to_string(i) + " is NaN or Inf");
    }
  }
  return points;
}

std::optional<CameraRig> FitCameraRig(const std::vector<ViewerSource>& sources, const Eigen::Vector3d& up,
                                      const Eigen::AlignedBox3f& extent) {
  constexpr size_t kMinCameras = 3;
  if (sources.size() < kMinCameras || extent.isEmpty()) return std::nullopt;
  // Least squares: the point whose summed squared distance to the optical axes is least,
  // sum (I - d d^T) x = sum (I - d d^T) c.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const ViewerSource& source : sources) {
    const Eigen::Vector3d d = source.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ();
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += across;
    b += across * CameraCenter(source.cam_from_world);
  }
  // Parallel axes (a walk looking ahead) leave the point undetermined along them.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a);
  if (eigen.eigenvalues()[0] < 0.02 * static_cast<double>(sources.size())) return std::nullopt;
  CameraRig rig;
  rig.target = a.ldlt().solve(b);
  const Eigen::Vector3f grow = Eigen::Vector3f::Constant(0.5f * extent.diagonal().norm());
  const Eigen::AlignedBox3f near_extent(extent.min() - grow, extent.max() + grow);
  if (!rig.target.allFinite() || !near_extent.contains(rig.target.cast<float>())) return std::nullopt;
  std::vector<double> distances, elevations, half_width_tans;
  size_t in_front = 0;
  for (const ViewerSource& source : sources) {
    in_front += (source.cam_from_world * rig.target).z() > 0;
    const Eigen::Vector3d offset = CameraCenter(source.cam_from_world) - rig.target;
    distances.push_back(offset.norm());
    half_width_tans.push_back(0.5 * static_cast<double>(source.camera.width) / source.camera.FocalX());
    elevations.push_back(std::asin(std::clamp(up.dot(offset) / std::max(offset.norm(), 1e-12), -1.0, 1.0)) * 180 /
                         std::numbers::pi);
  }
  if (4 * in_front < 3 * sources.size()) return std::nullopt;
  const auto median = [](std::vector<double>& values) {
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    return values[values.size() / 2];
  };
  rig.distance = median(distances);
  rig.elevation_deg = median(elevations);
  rig.half_width_tan = median(half_width_tans);
  if (!(rig.distance > 0)) return std::nullopt;
  return rig;
}

void FinishViewerScene(ViewerScene& scene) {
  if (scene.mesh.triangles.empty() && scene.points.empty()) {
    throw BadInputError("the scene has neither a mesh nor a point cloud");
  }
  scene.bounds.setEmpty();
  for (const Eigen::Vector3f& v : scene.mesh.vertices) scene.bounds.extend(v);
  for (const ColoredPoint& p : scene.points) scene.bounds.extend(p.position);
  // What is shown: the mesh, sampled by area so a large ground of two triangles weighs as much
  // as it covers, else the cloud.
  constexpr size_t kSamples = 200000;
  std::vector<Eigen::Vector3f> shown =
      scene.mesh.triangles.empty() ? Subsample(scene.points, kSamples) : SampleMesh(scene.mesh, 20000);
  scene.extent = RobustBounds(shown);
  // The ground is fitted to the cloud when there is one: the mesh was made from it.
  const std::vector<Eigen::Vector3f> ground_samples =
      scene.points.empty() ? shown : Subsample(scene.points, kSamples);
  const std::optional<Eigen::Vector3d> cameras_up = CamerasUp(scene.sources);
  const GroundPlaneOptions options;
  scene.ground = FitGroundPlane(ground_samples, cameras_up, options);
  scene.up = scene.ground ? scene.ground->normal : cameras_up.value_or(Eigen::Vector3d::UnitZ());
  // Mesh vertices too: area-weighted samples of a scene with a vast ground miss small objects.
  shown.insert(shown.end(), scene.mesh.vertices.begin(), scene.mesh.vertices.end());
  scene.focus = FocusBounds(shown, scene.ground, static_cast<float>(options.inlier_fraction_of_size) * scene.Radius() * 2);
  if (scene.focus.isEmpty()) scene.focus = scene.extent;
  // A vast ground can outweigh what stands on it (2% of the samples): keep that in the extent.
  scene.extent.extend(scene.focus);
  scene.rig = FitCameraRig(scene.sources, scene.up, scene.extent);
}

ViewerScene LoadViewerScene(const fs::path& workspace) {
  if (!fs::is_directory(workspace)) {
    throw BadInputError(workspace.string() + ": not a folder (expected a parallax workspace)");
  }
  ViewerScene scene;
  const Workspace ws(workspace);
  const fs::path obj = ws.Mesh();
  const fs::path ply = ws.Fused();
  if (fs::exists(obj)) scene.mesh = ReadTexturedMesh(obj);
  const fs::path display = ws.DisplayMesh();
  if (!scene.mesh.triangles.empty() && fs::exists(display)) scene.display_mesh = ReadTexturedMesh(display);
  if (fs::exists(ply)) scene.points = ReadColoredPly(ply);
  if (scene.mesh.triangles.empty() && scene.points.empty()) {
    throw BadInputError(workspace.string() +
                        ": nothing to show: no mesh/mesh.obj and no fused.ply in this folder "
                        "(run 'parallax reconstruct' first)");
  }
  const SceneFolder scene_folder{workspace};
  if (DetectSparseFormat(ws.Sparse())) {
    scene.sources = ReadSources(ws.Sparse(), ws.Images(), ReadWorkspaceColorGains(workspace));
  } else if (DetectSparseFormat(scene_folder.Training().sparse)) {
    scene.sources = ReadSources(scene_folder.Training().sparse, scene_folder.Training().images, {});
  }
  FinishViewerScene(scene);
  return scene;
}

}  // namespace parallax

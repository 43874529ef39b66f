#include "geometry/scene_frame.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <tuple>

#include <Eigen/Dense>

#include "core/angles.h"
#include "core/error.h"
#include "geometry/obj.h"
#include "geometry/ply.h"
#include "geometry/robust_bounds.h"

namespace parallax {
namespace {

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
std::vector<Eigen::Vector3f> Subsample(const std::vector<Eigen::Vector3f>& points, size_t count) {
  const size_t stride = std::max<size_t>(1, (points.size() + count - 1) / count);
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(points.size() / stride + 1);
  for (size_t i = 0; i < points.size(); i += stride) positions.push_back(points[i]);
  return positions;
}

Eigen::Vector3d OpticalAxis(const FrameCamera& camera) {
  return camera.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ();
}

// The frame of cameras alone (FitSceneFrame): their centres and the point they look at stand
// for the scene, which nothing else locates.
SceneFrame CamerasOnlyFrame(const std::vector<FrameCamera>& cameras) {
  if (cameras.empty()) throw InternalError("FitSceneFrame: no triangles, no points and no cameras");
  std::vector<Eigen::Vector3f> stand_ins;
  for (const FrameCamera& camera : cameras) stand_ins.push_back(CameraCenter(camera.cam_from_world).cast<float>());
  if (const std::optional<Eigen::Vector3d> looked_at = LookedAtPoint(cameras)) stand_ins.push_back(looked_at->cast<float>());
  SceneFrame frame;
  frame.bounds.setEmpty();
  for (const Eigen::Vector3f& p : stand_ins) frame.bounds.extend(p);
  frame.extent = RobustBounds(stand_ins);
  frame.focus = frame.extent;
  frame.up = CamerasUp(cameras).value_or(Eigen::Vector3d::UnitZ());
  frame.rig = FitCameraRig(cameras, frame.up, frame.extent);
  return frame;
}

}  // namespace

std::optional<Eigen::Vector3d> LookedAtPoint(const std::vector<FrameCamera>& cameras) {
  constexpr size_t kMinCameras = 3;
  // Per camera, the least eigenvalue of the normal matrix below which the axes count as
  // parallel; each camera adds I - d d^T, whose eigenvalues are 0, 1, 1.
  constexpr double kMinSpreadPerCamera = 0.02;
  if (cameras.size() < kMinCameras) return std::nullopt;
  // Least squares: the point whose summed squared distance to the optical axes is least,
  // sum (I - d d^T) x = sum (I - d d^T) c.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const FrameCamera& camera : cameras) {
    const Eigen::Vector3d d = OpticalAxis(camera);
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += across;
    b += across * CameraCenter(camera.cam_from_world);
  }
  // Parallel axes (a walk looking ahead) leave the point undetermined along them.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a);
  if (eigen.eigenvalues()[0] < kMinSpreadPerCamera * static_cast<double>(cameras.size())) return std::nullopt;
  const Eigen::Vector3d point = a.ldlt().solve(b);
  if (!point.allFinite()) return std::nullopt;
  return point;
}

std::optional<Eigen::Vector3d> CamerasUp(const std::vector<FrameCamera>& cameras) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const FrameCamera& camera : cameras) {
    sum += camera.cam_from_world.rotation.conjugate() * Eigen::Vector3d(0, -1, 0);
  }
  if (cameras.empty() || sum.norm() < 0.3 * static_cast<double>(cameras.size())) return std::nullopt;
  return sum.normalized();
}

std::optional<CameraRig> FitCameraRig(const std::vector<FrameCamera>& cameras, const Eigen::Vector3d& up,
                                      const Eigen::AlignedBox3f& extent) {
  if (extent.isEmpty()) return std::nullopt;
  const std::optional<Eigen::Vector3d> looked_at = LookedAtPoint(cameras);
  if (!looked_at) return std::nullopt;
  CameraRig rig;
  rig.target = *looked_at;
  const Eigen::Vector3f grow = Eigen::Vector3f::Constant(0.5f * extent.diagonal().norm());
  const Eigen::AlignedBox3f near_extent(extent.min() - grow, extent.max() + grow);
  if (!near_extent.contains(rig.target.cast<float>())) return std::nullopt;
  std::vector<double> distances, elevations, half_width_tans, azimuths;
  size_t in_front = 0;
  for (const FrameCamera& camera : cameras) {
    in_front += (camera.cam_from_world * rig.target).z() > 0;
    const Eigen::Vector3d offset = CameraCenter(camera.cam_from_world) - rig.target;
    azimuths.push_back(AzimuthDeg(offset, up));
    distances.push_back(offset.norm());
    half_width_tans.push_back(0.5 * static_cast<double>(camera.camera.width) / camera.camera.FocalX());
    elevations.push_back(std::asin(std::clamp(up.dot(offset) / std::max(offset.norm(), 1e-12), -1.0, 1.0)) * 180 /
                         std::numbers::pi);
  }
  if (4 * in_front < 3 * cameras.size()) return std::nullopt;
  const auto median = [](std::vector<double>& values) {
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    return values[values.size() / 2];
  };
  rig.distance = median(distances);
  rig.elevation_deg = median(elevations);
  rig.half_width_tan = median(half_width_tans);
  std::tie(rig.arc_start_deg, rig.arc_span_deg) = AzimuthArc(azimuths);
  if (!(rig.distance > 0)) return std::nullopt;
  return rig;
}

std::pair<double, double> AzimuthArc(std::vector<double> azimuths_deg) {
  if (azimuths_deg.size() < 2) return {0, 360};
  for (double& azimuth : azimuths_deg) azimuth -= 360 * std::floor(azimuth / 360);
  std::sort(azimuths_deg.begin(), azimuths_deg.end());
  // The gap from the last azimuth round to the first, then between neighbours.
  double widest = azimuths_deg.front() + 360 - azimuths_deg.back();
  double start = azimuths_deg.front();
  for (size_t i = 1; i < azimuths_deg.size(); ++i) {
    const double gap = azimuths_deg[i] - azimuths_deg[i - 1];
    if (gap > widest) {
      widest = gap;
      start = azimuths_deg[i];
    }
  }
  return {start, 360 - widest};
}

SceneFrame FitSceneFrame(const TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& cloud,
                         const std::vector<FrameCamera>& cameras) {
  if (mesh.triangles.empty() && cloud.empty()) return CamerasOnlyFrame(cameras);
  SceneFrame frame;
  frame.bounds.setEmpty();
  for (const Eigen::Vector3f& v : mesh.vertices) frame.bounds.extend(v);
  for (const Eigen::Vector3f& p : cloud) frame.bounds.extend(p);
  // What the scene is: the mesh, sampled by area so a large ground of two triangles weighs as
  // much as it covers, else the cloud.
  constexpr size_t kSamples = 200000;
  std::vector<Eigen::Vector3f> shown = mesh.triangles.empty() ? Subsample(cloud, kSamples) : SampleMesh(mesh, 20000);
  frame.extent = RobustBounds(shown);
  // The ground is fitted to the cloud when there is one: the mesh was made from it.
  const std::vector<Eigen::Vector3f> ground_samples = cloud.empty() ? shown : Subsample(cloud, kSamples);
  const std::optional<Eigen::Vector3d> cameras_up = CamerasUp(cameras);
  const GroundPlaneOptions options;
  frame.ground = FitGroundPlane(ground_samples, cameras_up, options);
  frame.up = frame.ground ? frame.ground->normal : cameras_up.value_or(Eigen::Vector3d::UnitZ());
  // Mesh vertices too: area-weighted samples of a scene with a vast ground miss small objects.
  shown.insert(shown.end(), mesh.vertices.begin(), mesh.vertices.end());
  frame.focus = FocusBounds(shown, frame.ground, static_cast<float>(options.inlier_fraction_of_size) * frame.Radius() * 2);
  if (frame.focus.isEmpty()) frame.focus = frame.extent;
  // A vast ground can outweigh what stands on it (2% of the samples): keep that in the extent.
  frame.extent.extend(frame.focus);
  frame.rig = FitCameraRig(cameras, frame.up, frame.extent);
  return frame;
}

SceneGeometry ReadSceneGeometry(const SceneFiles& files) {
  SceneGeometry geometry;
  if (std::filesystem::exists(files.mesh)) geometry.mesh = ReadTexturedMesh(files.mesh);
  if (std::filesystem::exists(files.cloud)) geometry.cloud = ReadPly(files.cloud);
  return geometry;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> GroundAxes(const Eigen::Vector3d& up) {
  const Eigen::Vector3d reference = std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = (reference - up * up.dot(reference)).normalized();
  return {u, up.cross(u)};
}

double AzimuthDeg(const Eigen::Vector3d& offset, const Eigen::Vector3d& up) {
  const auto [u, v] = GroundAxes(up);
  const double degrees = std::atan2(offset.dot(v), offset.dot(u)) * 180 / std::numbers::pi;
  return degrees < 0 ? degrees + 360 : degrees;
}

Rigid3d OrbitPose(const Eigen::Vector3d& centre, const Eigen::Vector3d& up, double azimuth_deg,
                  double elevation_deg, double distance) {
  const auto [u, v] = GroundAxes(up);
  // Keep clear of the poles, where LookAt's "up" is parallel to the view.
  const double elevation = Radians(std::clamp(elevation_deg, -89.0, 89.0));
  const double azimuth = Radians(azimuth_deg);
  const Eigen::Vector3d offset =
      std::cos(elevation) * (std::cos(azimuth) * u + std::sin(azimuth) * v) + std::sin(elevation) * up;
  return LookAt(centre + distance * offset, centre, up);
}

Orbit DefaultOrbit(const SceneFrame& frame, double azimuth_deg, std::optional<double> elevation_deg,
                   const Camera& camera) {
  if (frame.rig) {
    // As far as the photos' width of the scene needs with this camera's field of view.
    const double view_tan = 0.5 * static_cast<double>(camera.width) / camera.FocalX();
    const double scale = std::clamp(frame.rig->half_width_tan / view_tan, 0.25, 4.0);
    return Orbit{frame.rig->target, scale * frame.rig->distance, elevation_deg.value_or(frame.rig->elevation_deg)};
  }
  Orbit orbit{frame.FocusCentre().cast<double>(), 1, elevation_deg.value_or(30)};
  // The camera's rotation does not depend on the distance d: a corner at q = R (p - target)
  // seen from distance d has depth q.z + d and must satisfy f |q.x| / (q.z + d) <= kFill W / 2
  // (and likewise in y).
  constexpr double kFill = 0.8;
  const Eigen::Quaterniond rotation = OrbitPose(orbit.target, frame.up, azimuth_deg, orbit.elevation_deg, 1).rotation;
  const double half_w = 0.5 * kFill * static_cast<double>(camera.width);
  const double half_h = 0.5 * kFill * static_cast<double>(camera.height);
  const double size = std::max(1e-6, static_cast<double>(frame.focus.diagonal().norm()));
  double distance = 1e-3 * size;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d q =
        rotation * (frame.focus.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>() - orbit.target);
    distance = std::max({distance, camera.FocalX() * std::abs(q.x()) / half_w - q.z(),
                         camera.FocalY() * std::abs(q.y()) / half_h - q.z(), 1e-3 * size - q.z()});
  }
  orbit.distance = distance;
  return orbit;
}

Rigid3d DefaultOrbitPose(const SceneFrame& frame, double azimuth_deg, std::optional<double> elevation_deg,
                         const Camera& camera) {
  const Orbit orbit = DefaultOrbit(frame, azimuth_deg, elevation_deg, camera);
  return OrbitPose(orbit.target, frame.up, azimuth_deg, orbit.elevation_deg, orbit.distance);
}

}  // namespace parallax

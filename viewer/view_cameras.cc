#include "viewer/view_cameras.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "viewer/view_math.h"

namespace parallax {

namespace {

// The index of the source whose image name or stem is `name`. Throws BadInputError listing a
// few names when none matches.
int FindSource(const ViewerScene& scene, const std::string& name) {
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    if (scene.sources[i].name == name || std::filesystem::path(scene.sources[i].name).stem() == name) {
      return static_cast<int>(i);
    }
  }
  std::string known;
  for (size_t i = 0; i < scene.sources.size() && i < 5; ++i) known += (i ? ", " : "") + scene.sources[i].name;
  if (scene.sources.size() > 5) known += ", ...";
  throw BadInputError("--camera " + name + ": no source camera of that name or stem" +
                      (known.empty() ? " (the workspace has no sparse model)" : " (there are: " + known + ")"));
}

}  // namespace

std::optional<int> SourceIndex(const ViewerScene& scene, const std::string& name) {
  if (name.empty()) return std::nullopt;
  return FindSource(scene, name);
}

ViewCamera SourceViewCamera(const ViewerScene& scene, const std::string& name) {
  const ViewerSource& source = scene.sources[static_cast<size_t>(FindSource(scene, name))];
  const Camera camera = MakePinholeCamera(source.camera.id, source.camera.width, source.camera.height,
                                          source.camera.FocalX(), source.camera.FocalY(),
                                          source.camera.PrincipalX(), source.camera.PrincipalY());
  return ViewCamera{camera, source.cam_from_world, 0};
}

Orbit DefaultOrbit(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                   const Camera& camera) {
  if (scene.rig) {
    // As far as the photos' width of the scene needs with this camera's field of view.
    const double view_tan = 0.5 * static_cast<double>(camera.width) / camera.FocalX();
    const double scale = std::clamp(scene.rig->half_width_tan / view_tan, 0.25, 4.0);
    return Orbit{scene.rig->target, scale * scene.rig->distance, elevation_deg.value_or(scene.rig->elevation_deg)};
  }
  Orbit orbit{scene.FocusCentre().cast<double>(), 1, elevation_deg.value_or(30)};
  // The camera's rotation does not depend on the distance d: a corner at q = R (p - target)
  // seen from distance d has depth q.z + d and must satisfy f |q.x| / (q.z + d) <= kFill W / 2
  // (and likewise in y).
  constexpr double kFill = 0.8;
  const Eigen::Quaterniond rotation = OrbitPose(orbit.target, scene.up, azimuth_deg, orbit.elevation_deg, 1).rotation;
  const double half_w = 0.5 * kFill * static_cast<double>(camera.width);
  const double half_h = 0.5 * kFill * static_cast<double>(camera.height);
  const double size = std::max(1e-6, static_cast<double>(scene.focus.diagonal().norm()));
  double distance = 1e-3 * size;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d q =
        rotation * (scene.focus.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>() - orbit.target);
    distance = std::max({distance, camera.FocalX() * std::abs(q.x()) / half_w - q.z(),
                         camera.FocalY() * std::abs(q.y()) / half_h - q.z(), 1e-3 * size - q.z()});
  }
  orbit.distance = distance;
  return orbit;
}

ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                           int width, int height, double fov_deg) {
  const Camera camera = ViewerCamera(width, height, fov_deg);
  const Orbit orbit = DefaultOrbit(scene, azimuth_deg, elevation_deg, camera);
  return ViewCamera{camera, OrbitPose(orbit.target, scene.up, azimuth_deg, orbit.elevation_deg, orbit.distance), 0};
}

ViewCamera ScaledSourceViewCamera(const ViewerSource& source, int width, int height) {
  const double scale = static_cast<double>(width) / static_cast<double>(source.camera.width);
  const Camera camera = MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height),
                                          source.camera.FocalX() * scale, source.camera.FocalY() * scale,
                                          0.5 * width, 0.5 * height);
  return ViewCamera{camera, source.cam_from_world, 0};
}

}  // namespace parallax

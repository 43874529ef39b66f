#include "viewer/view_cameras.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "core/error.h"
#include "viewer/view_math.h"

namespace parallax {

ViewCamera SourceViewCamera(const ViewerScene& scene, const std::string& name) {
  for (const SourceView& source : scene.sources) {
    if (source.name == name || std::filesystem::path(source.name).stem() == name) {
      Camera camera = MakePinholeCamera(source.camera.id, source.camera.width, source.camera.height,
                                        source.camera.FocalX(), source.camera.FocalY(),
                                        source.camera.PrincipalX(), source.camera.PrincipalY());
      return ViewCamera{camera, source.cam_from_world, 0};
    }
  }
  std::string known;
  for (size_t i = 0; i < scene.sources.size() && i < 5; ++i) known += (i ? ", " : "") + scene.sources[i].name;
  if (scene.sources.size() > 5) known += ", ...";
  throw BadInputError("--camera " + name + ": no source camera of that name or stem" +
                      (known.empty() ? " (the workspace has no sparse model)" : " (there are: " + known + ")"));
}

ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, double elevation_deg,
                           int width, int height, double fov_deg) {
  const Camera camera = ViewerCamera(width, height, fov_deg);
  // The narrower of the two fields of view must hold the bounding sphere.
  const double half_fov = std::atan(0.5 * std::min(width, height) / camera.FocalX());
  const double distance = 1.05 * static_cast<double>(scene.FocusRadius()) / std::sin(half_fov);
  return ViewCamera{camera,
                    OrbitPose(scene.FocusCentre().cast<double>(), scene.up, azimuth_deg, elevation_deg,
                              std::max(distance, 1e-6)),
                    0};
}

ViewCamera ScaledSourceViewCamera(const SourceView& source, int width, int height) {
  const double scale = static_cast<double>(width) / static_cast<double>(source.camera.width);
  const Camera camera = MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height),
                                          source.camera.FocalX() * scale, source.camera.FocalY() * scale,
                                          0.5 * width, 0.5 * height);
  return ViewCamera{camera, source.cam_from_world, 0};
}

}  // namespace parallax

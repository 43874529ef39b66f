#include "viewer/view_cameras.h"

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

ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                           int width, int height, double fov_deg) {
  const Camera camera = ViewerCamera(width, height, fov_deg);
  return ViewCamera{camera, DefaultOrbitPose(scene, azimuth_deg, elevation_deg, camera), 0};
}

ViewCamera ScaledSourceViewCamera(const ViewerSource& source, int width, int height) {
  const double scale = static_cast<double>(width) / static_cast<double>(source.camera.width);
  const Camera camera = MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height),
                                          source.camera.FocalX() * scale, source.camera.FocalY() * scale,
                                          0.5 * width, 0.5 * height);
  return ViewCamera{camera, source.cam_from_world, 0};
}

}  // namespace parallax

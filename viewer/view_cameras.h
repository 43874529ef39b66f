#pragma once
// The viewpoints `parallax view` renders from: a source camera of the workspace, or an orbit
// around the scene's centre with the ground horizontal.
#include <optional>
#include <string>

#include <Eigen/Core>

#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax {

// The source camera whose image name or stem (name without extension) is `name`, with its
// own intrinsics and pose. Throws BadInputError listing a few names when none matches.
ViewCamera SourceViewCamera(const ViewerScene& scene, const std::string& name);

// The index in scene.sources of the camera named `name` (image name or stem); nullopt for an
// empty name. Throws BadInputError, as SourceViewCamera does, when none matches.
std::optional<int> SourceIndex(const ViewerScene& scene, const std::string& name);

// An orbit about the scene: the point looked at, the distance to it and the elevation above
// the ground (the azimuth is the caller's).
struct Orbit {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double distance = 1;       // Scene units.
  double elevation_deg = 30;
};

// The orbit that shows the scene as its photos do: with a camera rig (ViewerScene::rig), the
// rig's target and (unless `elevation_deg` is given) elevation, at the rig's distance scaled
// so `camera` sees as wide a slice of the scene as the photos (x0.25..4). Without one, the
// focus box's centre, `elevation_deg` or 30, and the distance at which the focus box's
// corners fill 80% of `camera`'s view from `azimuth_deg`.
Orbit DefaultOrbit(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                   const Camera& camera);

// A camera of `width` x `height` (horizontal field of view `fov_deg`) on the DefaultOrbit at
// `azimuth_deg`, looking at its target with the ground horizontal.
ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                           int width, int height, double fov_deg = 50);

// A source camera's view scaled to `width` x `height` (same field of view horizontally).
ViewCamera ScaledSourceViewCamera(const ViewerSource& source, int width, int height);

}  // namespace parallax

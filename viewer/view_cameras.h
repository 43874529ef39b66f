#pragma once
// The viewpoints `parallax view` renders from: a source camera of the workspace, or an orbit
// around the scene with the ground horizontal (DefaultOrbit and OrbitPose of
// geometry/scene_frame.h, the orbit `parallax render --path orbit:N` follows too).
#include <optional>
#include <string>

#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax {

// The source camera whose image name or stem (name without extension) is `name`, with its
// own intrinsics and pose. Throws BadInputError listing a few names when none matches.
ViewCamera SourceViewCamera(const ViewerScene& scene, const std::string& name);

// The index in scene.sources of the camera named `name` (image name or stem); nullopt for an
// empty name. Throws BadInputError, as SourceViewCamera does, when none matches.
std::optional<int> SourceIndex(const ViewerScene& scene, const std::string& name);

// A camera of `width` x `height` (horizontal field of view `fov_deg`, ViewerCamera) on the
// DefaultOrbit at `azimuth_deg` (DefaultOrbitPose), looking at its target with the ground
// horizontal.
ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, std::optional<double> elevation_deg,
                           int width, int height, double fov_deg = 50);

// A source camera's view scaled to `width` x `height` (same field of view horizontally).
ViewCamera ScaledSourceViewCamera(const ViewerSource& source, int width, int height);

}  // namespace parallax

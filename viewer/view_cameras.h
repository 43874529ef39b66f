#pragma once
// The viewpoints `parallax view` renders from: a source camera of the workspace, or an orbit
// around the scene's centre with the ground horizontal.
#include <string>

#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax {

// The source camera whose image name or stem (name without extension) is `name`, with its
// own intrinsics and pose. Throws BadInputError listing a few names when none matches.
ViewCamera SourceViewCamera(const ViewerScene& scene, const std::string& name);

// A camera of `width` x `height` (horizontal field of view `fov_deg`) on a circle about the
// scene's up axis through its centre, at `azimuth_deg` and `elevation_deg` above the ground,
// far enough that the scene's bounding sphere fits the view.
ViewCamera OrbitViewCamera(const ViewerScene& scene, double azimuth_deg, double elevation_deg,
                           int width, int height, double fov_deg = 50);

// A source camera's view scaled to `width` x `height` (same field of view horizontally).
ViewCamera ScaledSourceViewCamera(const SourceView& source, int width, int height);

}  // namespace parallax

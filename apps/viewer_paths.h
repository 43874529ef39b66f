#pragma once
// Where `parallax view FOLDER` reads the scene it shows.
#include <filesystem>

#include "viewer/viewer_scene.h"

namespace parallax {

// A workspace's mesh, its display copy, its cloud, and its photos with their cameras and color
// gains; for a scene folder (gt/sparse, images/), its training cameras and photos.
ViewerScenePaths ViewerScenePathsFor(const std::filesystem::path& folder);

}  // namespace parallax

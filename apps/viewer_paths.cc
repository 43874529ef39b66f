#include "apps/viewer_paths.h"

#include "core/sparse_model.h"
#include "core/workspace.h"

namespace parallax {

ViewerScenePaths ViewerScenePathsFor(const std::filesystem::path& folder) {
  const Workspace workspace(folder);
  const ViewSetPaths photos =
      DetectSparseFormat(workspace.Sparse()) ? workspace.Sources() : SceneFolder{folder}.Training();
  return {folder, workspace.Geometry(), workspace.DisplayMesh(), photos};
}

}  // namespace parallax

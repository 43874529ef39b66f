#include "pipeline/fusion_workspace.h"

#include <filesystem>
#include <vector>

#include "core/color_gains.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/sparse_model.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// The model's images that have a depth map and a geometric normal map.
std::vector<const SparseImage*> ViewsWithDepth(const Workspace& workspace, const SparseModel& model) {
  std::vector<const SparseImage*> views;
  for (const SparseImage& image : model.Images()) {
    if (fs::exists(workspace.Depth(image.name)) &&
        fs::exists(workspace.StereoNormalMap(image.name, StereoPass::kGeometric))) {
      views.push_back(&image);
    }
  }
  return views;
}

}  // namespace

FusedPoints FuseWorkspace(const Workspace& workspace, const FusionOptions& options, Progress& progress) {
  options.Check();
  const SparseModel model = ReadSparseModelWithoutKeypoints(workspace.Sparse());
  const std::vector<const SparseImage*> views = ViewsWithDepth(workspace, model);
  const ColorGains gains = ReadWorkspaceColorGains(workspace.Root());
  const LoadFusionView load = [&workspace, &gains](const SparseImage& image) {
    FusionViewMaps maps;
    maps.depth = ReadDepthExr(workspace.Depth(image.name));
    maps.normals = ReadColmapArray(workspace.StereoNormalMap(image.name, StereoPass::kGeometric));
    maps.color = ReadImage(workspace.Image(image.name));
    maps.gain = gains.Of(image.name);
    return maps;
  };
  return FuseDepthMaps(model, views, load, options, progress);
}

}  // namespace parallax

#include "pipeline/dense_stages.h"

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/hash.h"
#include "geometry/ply.h"
#include "mesh/poisson.h"
#include "mvs/fusion.h"
#include "mvs/sgbm.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Bump when a stage's results change for the same options, so caches recompute.
constexpr const char* kMvsVersion = "patch-match-6";
constexpr const char* kFusionVersion = "fusion-1";
constexpr const char* kMeshVersion = "mesh-2";

MvsOptions MvsOptionsOf(const DepthRequest& request) {
  MvsOptions options = MvsOptionsFor(request.quality);
  if (request.sources > 0) options.views.max_sources = request.sources;
  options.image_scale = request.scale;
  options.only_views = request.views;
  return options;
}

}  // namespace

Stage DepthStage(const Workspace& workspace, const std::string& undistort_key,
                 const DepthRequest& request, Progress& progress, MvsSummary* summary) {
  Hasher hasher;
  hasher.Add(undistort_key)
      .Add(kMvsVersion)
      .Add(static_cast<uint64_t>(request.quality))
      .Add(static_cast<uint64_t>(request.stereo))
      .Add(static_cast<uint64_t>(request.sources))
      .Add(request.scale == 1 ? "" : "scale " + std::to_string(request.scale));
  for (const std::string& view : request.views) hasher.Add(view);
  Stage stage;
  stage.name = "depth";
  stage.key = hasher.Hex();
  const bool every_view = request.views.empty();
  if (every_view) {
    stage.outputs = {workspace.DepthViews()};
  } else {
    for (const std::string& view : request.views) stage.outputs.push_back(workspace.Depth(view));
  }
  stage.run = [workspace, request, every_view, summary, &progress] {
    const MvsOptions options = MvsOptionsOf(request);
    const MvsSummary mvs = request.stereo == StereoMethod::kSgbm
                               ? RunSgbmStereo(workspace.Root(), options.views, {}, progress)
                               : RunMultiViewStereo(workspace.Root(), options, progress);
    if (every_view) WriteFileAtomically(workspace.DepthViews(), nlohmann::json(mvs).dump(2) + "\n");
    if (summary) *summary = mvs;
  };
  return stage;
}

Stage FusionStage(const Workspace& workspace, const std::string& depth_key, Progress& progress) {
  Stage stage;
  stage.name = "fusion";
  stage.key = Hasher().Add(depth_key).Add(kFusionVersion).Hex();
  stage.outputs = {workspace.Fused()};
  stage.run = [workspace, &progress] {
    WritePly(workspace.Fused(), FuseWorkspace(workspace.Root(), {}, progress));
  };
  return stage;
}

Stage MeshStage(const Workspace& workspace, const std::string& depth_key, Quality quality,
                const Colmap& colmap, Progress& progress) {
  Stage stage;
  stage.name = "mesh";
  stage.key = Hasher()
                  .Add(depth_key)
                  .Add(kFusionVersion)
                  .Add(kMeshVersion)
                  .Add(static_cast<uint64_t>(quality))
                  .Hex();
  stage.outputs = {workspace.MeshSummary()};
  stage.run = [workspace, quality, &colmap, &progress] {
    const MeshSummary mesh =
        MeshWorkspace(workspace.Root(), colmap, MeshOptionsFor(quality), progress);
    WriteFileAtomically(workspace.MeshSummary(), nlohmann::json(mesh).dump(2) + "\n");
  };
  return stage;
}

std::string UndistortedModelKey(const Workspace& workspace, const StageGraph& graph) {
  if (const auto key = graph.CompletedKey("undistort")) return *key;
  return Hasher().Add(HashFolder(workspace.Sparse())).Hex();
}

}  // namespace parallax

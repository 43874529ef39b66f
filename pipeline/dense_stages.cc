#include "pipeline/dense_stages.h"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/hash.h"
#include "core/sparse_model.h"
#include "geometry/ply.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/fusion_workspace.h"
#include "pipeline/mesh_workspace.h"
#include "sfm/color_gains.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Bump when a stage's results change for the same options, so caches recompute.
constexpr const char* kMvsVersion = "patch-match-8";
constexpr const char* kFusionVersion = "fusion-6";
constexpr const char* kMeshVersion = "mesh-9";
constexpr const char* kColorGainsVersion = "color-gains-1";

// The working scale of every view, when one is below 1: what the results depend on, rather
// than the knobs that chose it (a cap above the photos' size changes nothing, and keeps the
// key of a workspace estimated before the cap existed).
std::string ScaleKey(const Workspace& workspace, const MvsOptions& options) {
  if (!DetectSparseFormat(workspace.Sparse())) {
    return "scale " + std::to_string(options.image_scale) + " cap " + std::to_string(options.max_image_size);
  }
  std::set<double> scales;
  const SparseModel model = ReadSparseModel(workspace.Sparse());
  for (const Camera& camera : model.Cameras()) {
    scales.insert(options.ScaleFor(static_cast<int>(camera.width), static_cast<int>(camera.height)));
  }
  if (scales == std::set<double>{1.0}) return "";
  std::string key = "scale";
  for (const double scale : scales) key += " " + std::to_string(scale);
  return key;
}

}  // namespace

DepthRequest DepthRequestOf(const ReconstructOptions& options) {
  DepthRequest request;
  request.quality = options.quality;
  request.stereo = options.stereo;
  request.sources = options.mvs_sources;
  request.scale = options.mvs_scale;
  request.max_size = options.mvs_max_size;
  request.seed = options.mvs_seed;
  return request;
}

MvsOptions MvsOptionsOf(const DepthRequest& request) {
  MvsOptions options = MvsOptionsFor(request.quality);
  if (request.sources > 0) options.views.max_sources = request.sources;
  if (request.scale > 0) {
    options.image_scale = request.scale;
    options.max_image_size = 0;
  }
  if (request.max_size > 0) options.max_image_size = request.max_size;
  options.only_views = request.views;
  options.seed = request.seed;
  return options;
}

std::string DescribeDepthResolution(const DepthRequest& request, int width, int height) {
  const MvsOptions options = MvsOptionsOf(request);
  const double scale = options.ScaleFor(width, height);
  const auto side = [scale](int pixels) { return std::to_string(std::max(1L, std::lround(pixels * scale))); };
  std::string why;
  if (request.max_size > 0) {
    why = "--mvs-max-size " + std::to_string(request.max_size);
  } else if (request.scale > 0) {
    char scale_text[32];
    std::snprintf(scale_text, sizeof scale_text, "%g", request.scale);
    why = std::string("--mvs-scale ") + scale_text;
  } else {
    why = std::string(QualityName(request.quality)) + " caps the long side at " +
          std::to_string(options.max_image_size) + " px (docs/depth.md: the best error for the time on real photos)";
  }
  char share[32];
  std::snprintf(share, sizeof share, "%.3g", scale);
  return "depth at " + side(width) + "x" + side(height) + " for " + std::to_string(width) + "x" +
         std::to_string(height) + " photos (scale " + share + "): " + why +
         (scale < 1 ? "; depth maps are written at that size and read at the photo's" : "");
}

Stage DepthStage(const Workspace& workspace, const std::string& undistort_key,
                 const DepthRequest& request, Progress& progress, MvsSummary* summary) {
  Hasher hasher;
  hasher.Add(undistort_key)
      .Add(kMvsVersion)
      .Add(static_cast<uint64_t>(request.quality))
      .Add(static_cast<uint64_t>(request.stereo))
      .Add(static_cast<uint64_t>(request.sources))
      .Add(ScaleKey(workspace, MvsOptionsOf(request)));
  // Seed 0 adds nothing: the default keeps the key it had before a seed could be chosen.
  if (request.seed != 0) hasher.Add("seed").Add(static_cast<uint64_t>(request.seed));
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
  stage.run = [workspace, request, every_view, summary, key = stage.key, &progress] {
    const MvsOptions options = MvsOptionsOf(request);
    const MvsSummary mvs = request.collect_blocks ? FinishMultiViewStereoBlocks(workspace, options)
                           : request.stereo == StereoMethod::kSgbm
                               ? RunSgbmStereo(workspace, options.views, {}, progress)
                               : RunMultiViewStereo(workspace, options, key, progress);
    if (every_view) WriteFileAtomically(workspace.DepthViews(), nlohmann::json(mvs).dump(2) + "\n");
    if (summary) *summary = mvs;
  };
  return stage;
}

Stage ColorGainsStage(const Workspace& workspace, const std::string& undistort_key, std::string* note) {
  Stage stage;
  stage.name = "color_gains";
  stage.key = Hasher().Add(undistort_key).Add(kColorGainsVersion).Hex();
  stage.outputs = {workspace.ColorGainsFile()};
  stage.run = [workspace, note] {
    const ColorGainsEstimate estimate = EstimateColorGains(ReadSparseModel(workspace.Sparse()), workspace.Images());
    WriteColorGains(workspace.ColorGainsFile(), estimate.gains);
    if (note) *note = "color gains: " + estimate.note;
  };
  return stage;
}

std::string EnsureColorGains(const Workspace& workspace) {
  // A workspace without photos (a bare SfM model) blends none.
  if (fs::exists(workspace.ColorGainsFile()) || !fs::is_directory(workspace.Images())) return "";
  StageGraph graph(workspace, false);
  std::string note;
  graph.Run(ColorGainsStage(workspace, UndistortedModelKey(workspace, graph), &note));
  return note;
}

Stage FusionStage(const Workspace& workspace, const DepthRequest& request, const std::string& depth_key,
                  const std::string& color_gains_key, Progress& progress) {
  Stage stage;
  stage.name = "fusion";
  stage.key = Hasher().Add(depth_key).Add(color_gains_key).Add(kFusionVersion).Hex();
  stage.outputs = {workspace.Fused()};
  const MvsOptions mvs = MvsOptionsOf(request);
  FusionOptions options;
  options.image_scale = mvs.image_scale;
  options.max_image_size = mvs.max_image_size;
  stage.run = [workspace, options, &progress] {
    WritePly(workspace.Fused(), FuseWorkspace(workspace, options, progress));
  };
  return stage;
}

namespace {

// The mean share of each photo's pixels the depth stage (and so fusion) works at.
double FusedPixelShare(const Workspace& workspace, const DepthRequest& request) {
  const MvsOptions options = MvsOptionsOf(request);
  const SparseModel model = ReadSparseModel(workspace.Sparse());
  double sum = 0;
  for (const Camera& camera : model.Cameras()) {
    const double scale = options.ScaleFor(static_cast<int>(camera.width), static_cast<int>(camera.height));
    sum += scale * scale;
  }
  return model.Cameras().empty() ? 1.0 : sum / static_cast<double>(model.Cameras().size());
}

}  // namespace

Stage MeshStage(const Workspace& workspace, const DepthRequest& request, const ReconstructOptions& reconstruct,
                const std::string& depth_key, const std::string& color_gains_key, const Colmap& colmap,
                Progress& progress) {
  MeshOptions options = MeshOptionsFor(request.quality);
  options.mesher = reconstruct.mesher;
  if (reconstruct.tsdf_voxel_pixels > 0) options.tsdf_voxel_pixels = reconstruct.tsdf_voxel_pixels;
  if (reconstruct.tsdf_min_weight > 0) options.tsdf_min_weight = static_cast<float>(reconstruct.tsdf_min_weight);
  Stage stage;
  stage.name = "mesh";
  Hasher key;
  key.Add(depth_key).Add(color_gains_key).Add(kFusionVersion).Add(kMeshVersion).Add(static_cast<uint64_t>(request.quality));
  if (options.mesher == Mesher::kTsdf) {
    key.Add("tsdf-1").Add(std::to_string(options.tsdf_voxel_pixels)).Add(std::to_string(options.tsdf_min_weight));
  }
  stage.key = key.Hex();
  stage.outputs = {workspace.MeshSummary()};
  stage.run = [workspace, request, options, &colmap, &progress] {
    MeshOptions trimmed = options;
    // A cloud fused from fewer pixels is less dense where it is complete.
    trimmed.poisson_trim += std::log2(FusedPixelShare(workspace, request));
    const MeshSummary mesh = MeshWorkspace(workspace, colmap, trimmed, progress);
    WriteFileAtomically(workspace.MeshSummary(), nlohmann::json(mesh).dump(2) + "\n");
  };
  return stage;
}

std::string UndistortedModelKey(const Workspace& workspace, const StageGraph& graph) {
  if (const auto key = graph.CompletedKey("undistort")) return *key;
  return Hasher().Add(HashFolder(workspace.Sparse())).Hex();
}

}  // namespace parallax

#pragma once
// The dense stages as data (pipeline/stage_graph.h): depth (multi-view stereo), fusion and
// the textured mesh, each keyed by the stage before it. `reconstruct` asks for depth of every
// view; `render` asks the same stage for the views its cameras use.
#include <cstdint>
#include <string>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"
#include "core/quality.h"
#include "core/workspace.h"
#include "mvs/mvs.h"
#include "pipeline/reconstruct_options.h"
#include "pipeline/stage_graph.h"

namespace parallax {

struct DepthRequest {
  Quality quality = Quality::kBalanced;
  StereoMethod stereo = StereoMethod::kPatchMatch;
  int sources = 0;   // Source views per depth map; 0: as `quality` says.
  // The working resolution (MvsOptions::image_scale, max_image_size). 0: as `quality`'s
  // long-side cap says. A scale alone lifts the cap (scale 1 is the photo's full size).
  double scale = 0;
  int max_size = 0;
  uint32_t seed = 0;  // MvsOptions::seed.
  // Only these views (image names); empty: every view, and depth/views.json is written.
  std::vector<std::string> views;
  // The views were estimated in blocks by other processes (RunMultiViewStereoBlock,
  // pipeline/depth_workspace.h): the stage only collects them. Not part of the key: the maps
  // are the same.
  bool collect_blocks = false;
};

// The depth `reconstruct` asks for with `options`.
DepthRequest DepthRequestOf(const ReconstructOptions& options);
// As <ws>/slurm/depth_request.json keeps it for the cluster's jobs (pipeline/slurm.h).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(DepthRequest, quality, stereo, sources, scale, max_size, seed)

// The stereo's options for `request`.
MvsOptions MvsOptionsOf(const DepthRequest& request);

// What resolution the depth stage works at for photos of `width` x `height`, and why.
std::string DescribeDepthResolution(const DepthRequest& request, int width, int height);

// Depth maps for `request`, computed from the undistorted workspace that `undistort_key`
// identifies. When it runs, the stage's summary goes to `*summary` (when not null).
Stage DepthStage(const Workspace& workspace, const std::string& undistort_key,
                 const DepthRequest& request, Progress& progress, MvsSummary* summary = nullptr);

// Each photo's exposure and white balance gain (sfm/color_gains.h), from the undistorted model
// and photos; its note goes to `*note` when it runs.
Stage ColorGainsStage(const Workspace& workspace, const std::string& undistort_key, std::string* note = nullptr);

// Runs the color gains stage through the workspace's graph when the workspace (made before
// gains were estimated) lacks them; returns what it did, or "" when they were there or the
// workspace has no photos.
std::string EnsureColorGains(const Workspace& workspace);

// Fusion and mesh take their colors from the photos, corrected by the gains that
// `color_gains_key` identifies. Fusion works at the depth stage's resolution (`request`, whose
// effect on the maps `depth_key` already holds).
Stage FusionStage(const Workspace& workspace, const DepthRequest& request, const std::string& depth_key,
                  const std::string& color_gains_key, Progress& progress);

// The surface by options.mesher (and its volume's voxel and weight); a Poisson stage keeps the
// key it had before the choice.
Stage MeshStage(const Workspace& workspace, const DepthRequest& request, const ReconstructOptions& options,
                const std::string& depth_key, const std::string& color_gains_key, const Colmap& colmap,
                Progress& progress);

// The key that identifies a workspace's undistorted model: the one its undistort stage
// completed with, or, for a workspace not made by reconstruct, a hash of its model files.
std::string UndistortedModelKey(const Workspace& workspace, const StageGraph& graph);

}  // namespace parallax

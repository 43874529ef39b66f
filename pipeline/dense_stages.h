#pragma once
// The dense stages as data (pipeline/stage_graph.h): depth (multi-view stereo), fusion and
// the textured mesh, each keyed by the stage before it. `reconstruct` asks for depth of every
// view; `render` asks the same stage for the views its cameras use.
#include <string>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"
#include "core/quality.h"
#include "core/workspace.h"
#include "mvs/mvs.h"
#include "pipeline/reconstruct.h"
#include "pipeline/stage_graph.h"

namespace parallax {

struct DepthRequest {
  Quality quality = Quality::kBalanced;
  StereoMethod stereo = StereoMethod::kPatchMatch;
  int sources = 0;   // Source views per depth map; 0: as `quality` says.
  double scale = 1;  // Resolution of the estimate (MvsOptions::image_scale).
  // Only these views (image names); empty: every view, and depth/views.json is written.
  std::vector<std::string> views;
};

// Depth maps for `request`, computed from the undistorted workspace that `undistort_key`
// identifies. When it runs, the stage's summary goes to `*summary` (when not null).
Stage DepthStage(const Workspace& workspace, const std::string& undistort_key,
                 const DepthRequest& request, Progress& progress, MvsSummary* summary = nullptr);

Stage FusionStage(const Workspace& workspace, const std::string& depth_key, Progress& progress);

Stage MeshStage(const Workspace& workspace, const std::string& depth_key, Quality quality,
                const Colmap& colmap, Progress& progress);

// The key that identifies a workspace's undistorted model: the one its undistort stage
// completed with, or, for a workspace not made by reconstruct, a hash of its model files.
std::string UndistortedModelKey(const Workspace& workspace, const StageGraph& graph);

}  // namespace parallax

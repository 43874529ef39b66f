#pragma once
// `parallax evaluate`: a workspace measured against a scene folder's ground truth, every part
// the workspace has: camera poses, depth maps, the fused cloud, the textured mesh and the
// scene's novel views rendered from the workspace.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "core/scene_folder.h"
#include "core/workspace.h"
#include "eval/cloud_evaluation.h"
#include "eval/depth_evaluation.h"
#include "eval/evaluation_layout.h"
#include "eval/evaluate.h"
#include "eval/mesh_evaluation.h"
#include "eval/novel_evaluation.h"
#include "reproject/workspace_depth.h"

namespace parallax {

// Where the novel cameras' poses come from, for workspace sources: registering their photos
// into the SfM model (as novel-view benchmarks do), or the ground truth mapped through the
// pose alignment.
enum class NovelPoses { kRegistered, kAligned };

struct EvaluateOptions {
  // Compare in the frame found by the pose alignment; false: the identity (a workspace made
  // with known cameras is in the ground truth's frame).
  bool align = true;
  // Render the novel views from the scene's ground-truth sources instead of the workspace's.
  bool gt_sources = false;
  // Only the novel views.
  bool novel_only = false;
  NovelPoses novel_poses = NovelPoses::kRegistered;
  NovelViewSettings novel;
  // Another workspace evaluated at the same held-out cameras: the textured mesh is also scored
  // on the pixels both meshes cover (its evaluation/mesh_held_out/<name>.covered.png).
  std::filesystem::path mesh_common_with;
  // Score this textured mesh (OBJ, or PLY with texture coordinates, such as OpenMVS's
  // TextureMesh writes) instead of the workspace's; its texture holds the photos' own colors,
  // so no color gains are applied. Empty: the workspace's mesh/mesh.obj.
  std::filesystem::path mesh;
};

struct MeshEvaluation {
  size_t triangles = 0;
  size_t vertices = 0;
  std::optional<CloudAccuracy> accuracy;  // Vertices against the ground-truth depth, if any.
  TexturedMeshScore texture;  // Renders from the workspace cameras against the photos.
  std::filesystem::path render_dir;
};

struct NovelViewsEvaluation {
  NovelEvaluation result;
  bool gt_sources = false;
  bool color_gains = false;  // The sources' photos were corrected by the workspace's gains.
  std::string poses;  // "ground truth", "registered" or "aligned".
  int poses_registered = 0;
  bool registration_tried = false;
  std::string registration_note;  // What the registration did, when tried, and what it did not.
  // The registered poses against the scene's novel ground truth, taken through the training
  // cameras' alignment: how far a photo added to the finished model lands from its true pose.
  std::vector<ImagePoseError> registered_pose_errors;
  std::string depth_holes_note;   // Workspace sources: where their depth holes came from.
  std::filesystem::path comparison_dir;
};

struct WorkspaceEvaluation {
  // reconstruct --hold-out's protocol: the held-out photos scored, no ground truth (`poses`
  // left empty).
  bool held_out = false;
  PoseEvaluation poses;
  std::optional<DepthEvaluation> depth;  // Present when some depth map has ground truth.
  bool depth_aligned = true;
  std::filesystem::path depth_error_dir;
  bool depth_without_truth = false;  // Depth maps exist, none of a ground-truth image.
  std::optional<CloudAccuracy> fused;
  std::optional<MeshEvaluation> mesh;
  // What the scene has no ground truth for (e.g. real photos without depth), and so was not
  // scored.
  std::vector<std::string> not_scored;
  std::optional<NovelViewsEvaluation> novel;
  // The textured mesh rendered at the novel (held-out) cameras, beside the warped views; when
  // the workspace has a mesh and the views are rendered from its sources.
  std::optional<TexturedMeshScore> mesh_held_out;
  std::filesystem::path mesh_held_out_dir;
  // Stage timings from reconstruct's report.json, when the workspace has them.
  std::optional<std::map<std::string, double>> reconstruct_timings_s;
};

// Evaluates every part `workspace` has against `scene`, writing the comparison images under
// EvaluationLayout(workspace.Root()).Dir(). Throws BadInputError when the workspace has no model or a
// ground-truth file cannot be read, ToolError when colmap fails to register held-out photos.
WorkspaceEvaluation EvaluateWorkspace(const Workspace& workspace, const SceneFolder& scene,
                                      const EvaluateOptions& options, Progress& progress);

// The photos `workspace` holds out (reconstruct --hold-out, Workspace::HeldOut) rendered at
// their cameras from the workspace's sources and compared with them, as novel-view benchmarks
// score real photos: no ground truth needed. Throws BadInputError when the workspace holds no
// photos out or has no depth maps.
WorkspaceEvaluation EvaluateHeldOut(const Workspace& workspace, const EvaluateOptions& options);

// The JSON evaluate writes (docs/design.md "evaluation.json").
void to_json(nlohmann::json& json, const WorkspaceEvaluation& evaluation);

}  // namespace parallax

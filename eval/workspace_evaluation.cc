#include "eval/workspace_evaluation.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/sparse_model.h"
#include "eval/register_held_out.h"
#include "geometry/ply.h"
#include "geometry/obj.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Whether `dir` holds depth maps `<stem>.exr` (confidence maps `<stem>.confidence.exr` aside).
bool HasDepthMaps(const fs::path& dir) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) return false;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && entry.path().extension() == ".exr" &&
        !name.ends_with(".confidence.exr")) {
      return true;
    }
  }
  return false;
}

// Stage timings recorded by reconstruct, when the workspace has them.
std::optional<std::map<std::string, double>> ReconstructTimings(const Workspace& workspace) {
  if (!fs::exists(workspace.Report())) return std::nullopt;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileBytes(workspace.Report()));
    return json.at("reconstruct").at("timings_s").get<std::map<std::string, double>>();
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// The textured mesh to score: another tool's (options.mesh) or the workspace's.
fs::path ScoredMeshPath(const Workspace& workspace, const EvaluateOptions& options) {
  return options.mesh.empty() ? workspace.Mesh() : options.mesh;
}

TriangleMesh ReadScoredMesh(const Workspace& workspace, const EvaluateOptions& options) {
  const fs::path path = ScoredMeshPath(workspace, options);
  return path.extension() == ".ply" ? ReadPly(path) : ReadTexturedMesh(path);
}

// The color gains the scored mesh's texture is corrected by: none for another tool's mesh.
ColorGains ScoredMeshGains(const Workspace& workspace, const EvaluateOptions& options) {
  return options.mesh.empty() ? ReadWorkspaceColorGains(workspace.Root()) : ColorGains();
}

MeshEvaluation EvaluateMesh(const Workspace& workspace, const SparseModel& estimate,
                            const SparseModel& truth, const SceneFolder& scene,
                            const Similarity3d& truth_from_estimate, bool truth_depth,
                            const EvaluateOptions& options) {
  const TriangleMesh mesh = ReadScoredMesh(workspace, options);
  MeshEvaluation result;
  result.triangles = mesh.triangles.size();
  result.vertices = mesh.vertices.size();
  if (truth_depth) {
    result.accuracy = MeasureCloud(mesh.vertices, truth, scene.Training().depth, truth_from_estimate);
  }
  result.render_dir = EvaluationLayout(workspace.Root()).MeshRenders();
  std::vector<std::string> names;
  const std::vector<NamedCamera> cameras = CamerasOfModel(estimate, &names);
  result.texture = ScoreTexturedMesh(mesh, cameras, names, ScoredMeshGains(workspace, options), workspace.Images(),
                                     result.render_dir);
  return result;
}

// The workspace's textured mesh at the novel cameras `targets`, photos `names` in `images`,
// into `evaluation`; nothing when the workspace has no mesh.
void ScoreMeshAtNovelCameras(const Workspace& workspace, const std::vector<NamedCamera>& targets,
                             const std::vector<std::string>& names, const fs::path& images,
                             const EvaluateOptions& options, WorkspaceEvaluation& evaluation) {
  if (!fs::exists(ScoredMeshPath(workspace, options))) return;
  evaluation.mesh_held_out_dir = EvaluationLayout(workspace.Root()).MeshHeldOutRenders();
  const fs::path common =
      options.mesh_common_with.empty() ? fs::path() : EvaluationLayout(options.mesh_common_with).MeshHeldOutRenders();
  evaluation.mesh_held_out = ScoreTexturedMesh(ReadScoredMesh(workspace, options), targets, names,
                                               ScoredMeshGains(workspace, options), images,
                                               evaluation.mesh_held_out_dir, common);
}

// `targets` rendered from the sources (the workspace's, or with options.gt_sources the
// scene's) and compared with the photos `names` in `truth`, into `evaluation`.
void RenderAndCompare(const Workspace& workspace, ViewSetPaths sources, const std::vector<NamedCamera>& targets,
                      const std::vector<std::string>& names, const ViewSetPaths& truth,
                      const EvaluateOptions& options, NovelViewsEvaluation& evaluation) {
  if (!options.novel.color_gains) sources.color_gains.clear();
  evaluation.color_gains = !sources.color_gains.empty() && fs::exists(sources.color_gains);
  SourceLibrary library(sources);
  library.DropViewsWithoutDepth();  // Views the depth stage could not estimate.
  if (!options.gt_sources) {
    evaluation.depth_holes_note = PrepareWorkspaceDepth(workspace.Mesh(), options.novel, &library).note;
  }
  evaluation.comparison_dir = EvaluationLayout(workspace.Root()).NovelComparisons(options.gt_sources);
  evaluation.result = EvaluateNovelViews(library, targets, names, truth, options.novel.selection,
                                         options.novel.render, evaluation.comparison_dir);
}

// The scene's novel cameras rendered from the workspace (cameras mapped into its frame) or,
// with gt_sources, from the scene's own training views and depth; compared with the novel
// images. Registered poses are measured against the truth through the training cameras'
// alignment (`poses`).
NovelViewsEvaluation EvaluateNovel(const Workspace& workspace, const SceneFolder& scene,
                                   const EvaluateOptions& options, const Similarity3d& truth_from_estimate,
                                   const PoseEvaluation& poses, Progress& progress,
                                   std::vector<NamedCamera>* targets_out, std::vector<std::string>* names_out) {
  NovelViewsEvaluation evaluation;
  evaluation.gt_sources = options.gt_sources;
  const SparseModel novel = ReadSparseModel(scene.Novel().sparse);
  const Similarity3d estimate_from_truth =
      options.gt_sources ? Similarity3d{} : truth_from_estimate.Inverse();
  std::vector<NamedCamera> targets;
  std::vector<std::string> names;
  for (const SparseImage& image : novel.Images()) {
    targets.push_back({fs::path(image.name).stem().string(),
                       {novel.CameraById(image.camera_id),
                        estimate_from_truth.TransformPose(image.cam_from_world)}});
    names.push_back(image.name);
  }
  evaluation.poses = options.gt_sources ? "ground truth" : "aligned";
  if (!options.gt_sources && options.novel_poses == NovelPoses::kRegistered) {
    const HeldOutRegistration registration = RegisterHeldOutPhotos(
        workspace.Root(), scene.Novel().images, names, EvaluationLayout(workspace.Root()).NovelRegistration(), progress);
    for (size_t i = 0; i < names.size(); ++i) {
      const auto found = registration.registered.find(names[i]);
      if (found == registration.registered.end()) continue;
      targets[i].camera = found->second;
      ++evaluation.poses_registered;
      evaluation.registered_pose_errors.push_back(PoseError(
          names[i], found->second.cam_from_world, novel.Images()[i].cam_from_world,
          poses.alignment.target_from_source, poses.extent));
    }
    evaluation.registration_tried = true;
    evaluation.registration_note = registration.note;
    if (evaluation.poses_registered < static_cast<int>(names.size())) {
      evaluation.registration_note += "; the others from the alignment";
    }
    if (evaluation.poses_registered > 0) evaluation.poses = "registered";
  }
  RenderAndCompare(workspace, options.gt_sources ? scene.Training() : SourcePathsFor(workspace.Root()), targets,
                   names, scene.Novel(), options, evaluation);
  *targets_out = std::move(targets);
  *names_out = std::move(names);
  return evaluation;
}

}  // namespace

WorkspaceEvaluation EvaluateWorkspace(const Workspace& workspace, const SceneFolder& scene,
                                      const EvaluateOptions& options, Progress& progress) {
  if (!DetectSparseFormat(workspace.Sparse())) {
    throw BadInputError(workspace.Sparse().string() + " holds no COLMAP model: run parallax "
                        "reconstruct first");
  }
  const SparseModel estimate = ReadSparseModel(workspace.Sparse());
  const SparseModel truth = ReadSparseModel(scene.Training().sparse);
  WorkspaceEvaluation evaluation;
  evaluation.poses = EvaluatePoses(estimate, truth);
  const Similarity3d truth_from_estimate =
      options.align ? evaluation.poses.alignment.target_from_source : Similarity3d{};

  const bool has_depth = HasDepthMaps(workspace.DepthDir());
  // Real photos come with cameras but (usually) without depth: everything else is scored.
  const bool truth_depth = fs::is_directory(scene.Training().depth);
  if (!truth_depth && !options.novel_only) {
    evaluation.not_scored.push_back("depth maps, fused cloud and mesh geometry: " + scene.root.string() +
                                    " has no ground-truth depth (gt/depth)");
  }
  if (!truth_depth && options.gt_sources) {
    throw BadInputError(scene.Training().depth.string() + " does not exist: --gt-sources renders "
                        "from the scene's ground-truth depth, which this scene does not have");
  }
  if (has_depth && truth_depth && !options.novel_only) {
    evaluation.depth_aligned = options.align;
    evaluation.depth_error_dir = EvaluationLayout(workspace.Root()).DepthErrorImages();
    DepthEvaluation depth = EvaluateDepth(estimate, workspace.DepthDir(), truth, scene.Training().depth,
                                          truth_from_estimate, evaluation.depth_error_dir);
    if (depth.views > 0) {
      evaluation.depth = std::move(depth);
    } else {
      evaluation.depth_without_truth = true;
    }
  }
  if (fs::exists(workspace.Fused()) && truth_depth && !options.novel_only) {
    evaluation.fused = MeasureCloud(ReadPly(workspace.Fused()).vertices, truth,
                                    scene.Training().depth, truth_from_estimate);
  }
  if (fs::exists(ScoredMeshPath(workspace, options)) && !options.novel_only) {
    evaluation.mesh = EvaluateMesh(workspace, estimate, truth, scene, truth_from_estimate, truth_depth, options);
  }
  if (fs::is_directory(scene.Novel().sparse) && (options.gt_sources || has_depth)) {
    std::vector<NamedCamera> targets;
    std::vector<std::string> names;
    evaluation.novel = EvaluateNovel(workspace, scene, options, truth_from_estimate,
                                     evaluation.poses, progress, &targets, &names);
    // The ground-truth sources' cameras are in the scene's frame, not the mesh's.
    if (!options.gt_sources) ScoreMeshAtNovelCameras(workspace, targets, names, scene.Novel().images, options, evaluation);
  }
  evaluation.reconstruct_timings_s = ReconstructTimings(workspace);
  return evaluation;
}

nlohmann::json BudgetJson(const LossBudget& budget) {
  const auto part = [](const PixelShareLoss& loss) {
    return nlohmann::json{{"share", loss.share}, {"psnr", loss.psnr}, {"db_lost", loss.db_lost}};
  };
  return {{"covered", part(budget.covered)},
          {"background", part(budget.background)},
          {"filled", part(budget.filled)},
          {"out_of_view_share", budget.out_of_view_share},
          {"exposure_db", budget.exposure_db},
          {"misalignment_px", {{"median", budget.misalignment.median_px}, {"p90", budget.misalignment.p90_px}}}};
}

WorkspaceEvaluation EvaluateHeldOut(const Workspace& workspace, const EvaluateOptions& options) {
  const Workspace held_out = workspace.HeldOut();
  if (!DetectSparseFormat(held_out.Sparse())) {
    throw BadInputError(workspace.Root().string() + " has no held-out photos (" + held_out.Sparse().string() +
                        "): reconstruct it with --hold-out or --hold-out-photos, or give --gt");
  }
  if (!HasDepthMaps(workspace.DepthDir())) {
    throw BadInputError(workspace.DepthDir().string() + " holds no depth maps to render the held-out photos from: "
                        "reconstruct without --no-depth");
  }
  if (options.gt_sources) throw BadInputError("--gt-sources needs a scene folder with ground truth (--gt)");
  std::vector<std::string> names;
  const std::vector<NamedCamera> targets = CamerasOfModel(ReadSparseModel(held_out.Sparse()), &names);
  WorkspaceEvaluation evaluation;
  evaluation.held_out = true;
  NovelViewsEvaluation& novel = evaluation.novel.emplace();
  novel.poses = "held out of the dense stages, registered with the others";
  ViewSetPaths truth;
  truth.images = held_out.Images();
  RenderAndCompare(workspace, SourcePathsFor(workspace.Root()), targets, names, truth, options, novel);
  ScoreMeshAtNovelCameras(workspace, targets, names, truth.images, options, evaluation);
  evaluation.reconstruct_timings_s = ReconstructTimings(workspace);
  return evaluation;
}

void to_json(nlohmann::json& json, const WorkspaceEvaluation& evaluation) {
  json = nlohmann::json::object();
  if (!evaluation.held_out) AddPoseSections(evaluation.poses, json);
  if (evaluation.depth) AddDepthSection(*evaluation.depth, json);
  if (evaluation.fused) {
    const CloudAccuracy& cloud = *evaluation.fused;
    json["fused"] = {{"points", cloud.points},
                     {"measured", cloud.measured},
                     {"median_relative_distance", cloud.median_relative_distance},
                     {"within_1pct", cloud.within_1pct}};
  }
  if (evaluation.mesh) {
    const MeshEvaluation& mesh = *evaluation.mesh;
    json["mesh"] = {{"triangles", mesh.triangles},
                    {"vertices", mesh.vertices},
                    {"textured_psnr_mean", mesh.texture.psnr_mean},
                    {"textured_coverage_mean", mesh.texture.coverage_mean}};
    if (mesh.accuracy) {
      json["mesh"]["median_relative_distance"] = mesh.accuracy->median_relative_distance;
      json["mesh"]["within_1pct"] = mesh.accuracy->within_1pct;
    }
  }
  if (evaluation.novel) {
    const NovelViewsEvaluation& novel = *evaluation.novel;
    const NovelEvaluation& result = novel.result;
    json["novel"] = {{"views", result.views},
                     {"psnr_mean", result.psnr_mean},
                     {"ssim_mean", result.ssim_mean},
                     {"psnr_valid_mean", result.psnr_valid_mean},
                     {"psnr_exposure_matched_mean", result.psnr_exposure_matched_mean},
                     {"hole_ratio_mean", result.hole_ratio_mean},
                     {"crack_ratio_mean", result.crack_ratio_mean},
                     {"out_of_view_ratio_mean", result.out_of_view_ratio_mean},
                     {"background_ratio_mean", result.background_ratio_mean},
                     {"hole_ratio_filled_mean", result.hole_ratio_filled_mean},
                     {"ms_per_view", result.ms_per_view},
                     {"gt_sources", novel.gt_sources},
                     {"color_gains", novel.color_gains},
                     {"poses", novel.poses},
                     {"poses_registered", novel.poses_registered},
                     {"budget_mean", BudgetJson(result.budget_mean)}};
    if (!novel.registered_pose_errors.empty()) {
      nlohmann::json& errors = json["novel"]["registered_pose_errors"] = nlohmann::json::array();
      for (const ImagePoseError& error : novel.registered_pose_errors) {
        errors.push_back({{"name", error.name},
                          {"rotation_error_deg", error.rotation_error_deg},
                          {"center_error_rel", error.center_error_rel}});
      }
    }
    nlohmann::json& per_view = json["novel"]["per_view"] = nlohmann::json::array();
    for (const NovelViewScore& view : result.per_view) {
      per_view.push_back({{"name", view.name},
                          {"psnr", view.psnr},
                          {"ssim", view.ssim},
                          {"psnr_valid", view.psnr_valid},
                          {"psnr_exposure_matched", view.psnr_exposure_matched},
                          {"hole_ratio", view.hole_ratio},
                          {"sources", view.sources},
                          {"budget", BudgetJson(view.budget)}});
    }
  }
  if (evaluation.mesh_held_out) {
    const TexturedMeshScore& mesh = *evaluation.mesh_held_out;
    json["mesh_held_out"] = {{"psnr_mean", mesh.frame_psnr_mean},
                             {"ssim_mean", mesh.frame_ssim_mean},
                             {"covered_psnr_mean", mesh.psnr_mean},
                             {"coverage_mean", mesh.coverage_mean}};
    nlohmann::json& per_view = json["mesh_held_out"]["per_view"] = nlohmann::json::array();
    for (const TexturedMeshView& view : mesh.per_view) {
      per_view.push_back({{"name", view.name},
                          {"psnr", view.psnr},
                          {"ssim", view.ssim},
                          {"covered_psnr", view.psnr_covered},
                          {"coverage", view.coverage}});
      if (view.common_share > 0) {
        per_view.back()["common_psnr"] = view.psnr_common;
        per_view.back()["common_share"] = view.common_share;
      }
    }
    if (mesh.common_share_mean > 0) {
      json["mesh_held_out"]["common_psnr_mean"] = mesh.common_psnr_mean;
      json["mesh_held_out"]["common_share_mean"] = mesh.common_share_mean;
    }
  }
  if (!evaluation.not_scored.empty()) json["not_scored"] = evaluation.not_scored;
  if (evaluation.reconstruct_timings_s) json["timings_s"] = *evaluation.reconstruct_timings_s;
}

}  // namespace parallax

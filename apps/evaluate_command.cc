#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/render_options.h"
#include "apps/terminal_progress.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "pipeline/depth_evaluation.h"
#include "pipeline/cloud_evaluation.h"
#include "pipeline/evaluate.h"
#include "pipeline/mesh_evaluation.h"
#include "pipeline/ply.h"
#include "pipeline/register_held_out.h"
#include "pipeline/textured_mesh.h"
#include "reproject/novel_evaluation.h"

namespace parallax {
namespace {

void PrintPoseTable(const PoseEvaluation& evaluation) {
  std::printf("%-24s %14s %16s\n", "image", "rotation (deg)", "centre (% extent)");
  for (const ImagePoseError& image : evaluation.images) {
    std::printf("%-24s %14.4f %16.4f\n", image.name.c_str(), image.rotation_error_deg,
                100 * image.center_error_rel);
  }
  for (const std::string& name : evaluation.missing) {
    std::printf("%-24s %14s %16s\n", name.c_str(), "missing", "missing");
  }
  std::printf("poses: %d/%d registered; rotation error mean %.4f, median %.4f, max %.4f deg; "
              "centre error mean %.4f%%, max %.4f%% of the %.3g extent; reprojection %.3f px\n",
              evaluation.registered, evaluation.total, evaluation.rotation_error_mean_deg,
              evaluation.rotation_error_median_deg, evaluation.rotation_error_max_deg,
              100 * evaluation.center_error_rel_mean, 100 * evaluation.center_error_rel_max,
              evaluation.extent, evaluation.reprojection_error_px);
  std::printf("alignment: scale %.6g, %d inliers\n", evaluation.alignment.target_from_source.scale,
              evaluation.alignment.inliers);
}

// Whether `dir` holds depth maps `<stem>.exr` (confidence maps `<stem>.confidence.exr` aside).
bool HasDepthMaps(const std::filesystem::path& dir) {
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error)) return false;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && entry.path().extension() == ".exr" &&
        !name.ends_with(".confidence.exr")) {
      return true;
    }
  }
  return false;
}

void PrintDepthSummary(const DepthEvaluation& evaluation, bool aligned,
                       const std::filesystem::path& error_image_dir) {
  std::printf("depth: %d views (%s); abs_rel median %.3f%%, signed median %+.3f%%; "
              "within 1%% %.1f%%, within 2%% %.1f%%; completeness %.1f%%; error images %s\n",
              evaluation.views, aligned ? "aligned" : "identity alignment",
              100 * evaluation.abs_rel_median, 100 * evaluation.signed_median,
              100 * evaluation.within_1pct, 100 * evaluation.within_2pct,
              100 * evaluation.completeness, error_image_dir.string().c_str());
}

// Stage timings recorded by reconstruct, when the workspace has them.
nlohmann::json ReconstructTimings(const std::filesystem::path& workspace) {
  const std::filesystem::path report = workspace / "report.json";
  if (!std::filesystem::exists(report)) return nullptr;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileBytes(report));
    return json.at("reconstruct").at("timings_s");
  } catch (const std::exception&) {
    return nullptr;
  }
}

// The textured mesh: its vertices against the ground-truth depth (like the fused cloud), and
// its renders from the workspace cameras against the photos.
nlohmann::json EvaluateMesh(const std::filesystem::path& obj, const SparseModel& estimate,
                            const std::filesystem::path& workspace, const SparseModel& truth,
                            const SceneFolder& scene, const Similarity3d& truth_from_estimate) {
  const TexturedMesh mesh = ReadTexturedMesh(obj);
  const CloudAccuracy accuracy =
      MeasureCloud(mesh.vertices, truth, scene.Training().depth, truth_from_estimate);
  const std::filesystem::path render_dir = workspace / "evaluation" / "mesh_render";
  const TexturedMeshScore texture =
      ScoreTexturedMesh(mesh, estimate, workspace / "images", render_dir);
  std::printf("mesh: %zu triangles; vertices: median relative distance %.3f%%, within 1%% "
              "%.1f%%; textured renders: %.2f dB PSNR on %.1f%% covered pixels (%s)\n",
              mesh.triangles.size(), 100 * accuracy.median_relative_distance,
              100 * accuracy.within_1pct, texture.psnr_mean, 100 * texture.coverage_mean,
              render_dir.string().c_str());
  return {{"triangles", mesh.triangles.size()},
          {"vertices", mesh.vertices.size()},
          {"median_relative_distance", accuracy.median_relative_distance},
          {"within_1pct", accuracy.within_1pct},
          {"textured_psnr_mean", texture.psnr_mean},
          {"textured_coverage_mean", texture.coverage_mean}};
}

// The scene's novel cameras rendered from the workspace (cameras mapped into its frame) or,
// with gt_sources, from the scene's own training views and depth; compared with the novel
// images.
nlohmann::json EvaluateNovel(const SceneFolder& scene, const std::filesystem::path& workspace,
                             bool gt_sources, bool register_poses,
                             const Similarity3d& truth_from_estimate,
                             const NovelViewSettings& settings) {
  const SparseModel novel = ReadSparseModel(scene.Novel().sparse);
  const Similarity3d estimate_from_truth =
      gt_sources ? Similarity3d{} : truth_from_estimate.Inverse();
  std::vector<NamedCamera> targets;
  std::vector<std::string> names;
  for (const SparseImage& image : novel.Images()) {
    targets.push_back({std::filesystem::path(image.name).stem().string(),
                       {novel.CameraById(image.camera_id),
                        estimate_from_truth.TransformPose(image.cam_from_world)}});
    names.push_back(image.name);
  }
  // Workspace sources: the novel cameras' poses by registering their photos into the SfM
  // model (as novel-view benchmarks do), where that works; else from the alignment.
  std::string poses = gt_sources ? "ground truth" : "aligned";
  int registered = 0;
  if (!gt_sources && register_poses) {
    TerminalProgress progress;
    const HeldOutRegistration registration = RegisterHeldOutPhotos(
        workspace, scene.Novel().images, names, workspace / "evaluation" / "novel_registration",
        progress);
    for (size_t i = 0; i < names.size(); ++i) {
      const auto found = registration.cam_from_world.find(names[i]);
      if (found == registration.cam_from_world.end()) continue;
      targets[i].camera.cam_from_world = found->second;
      ++registered;
    }
    std::printf("novel camera poses: %s%s\n", registration.note.c_str(),
                registered < static_cast<int>(names.size()) ? "; the others from the alignment" : "");
    if (registered > 0) poses = "registered";
  }
  SourceLibrary library(gt_sources ? scene.Training() : SourcePathsFor(workspace));
  library.DropViewsWithoutDepth();  // Views the depth stage could not estimate.
  if (!gt_sources) {
    std::printf("novel views: depth holes %s\n",
                PrepareWorkspaceDepth(workspace, settings, &library).note.c_str());
  }
  const std::filesystem::path comparison_dir =
      workspace / "evaluation" / (gt_sources ? "novel_gt_sources" : "novel");
  const NovelEvaluation result =
      EvaluateNovelViews(library, targets, names, scene.Novel(), settings.selection,
                         settings.render, comparison_dir);
  std::printf("%-16s %9s %7s %14s %7s\n", "novel view", "PSNR (dB)", "SSIM", "sampled (dB)", "holes");
  for (const NovelViewScore& view : result.per_view) {
    std::printf("%-16s %9.2f %7.3f %14.2f %6.2f%%\n", view.name.c_str(), view.psnr, view.ssim,
                view.psnr_valid, 100 * view.hole_ratio);
  }
  std::printf("novel views (%s): %d views; PSNR %.2f dB (%.2f dB on sampled pixels), SSIM %.3f; "
              "holes %.2f%% (cracks %.2f%%) -> %.2f%% after filling; out of view %.2f%%, "
              "background %.2f%%; %.1f ms per view; %d of %d sources loaded (%s)\n",
              gt_sources ? "ground-truth sources" : "workspace sources", result.views,
              result.psnr_mean, result.psnr_valid_mean, result.ssim_mean,
              100 * result.hole_ratio_mean, 100 * result.crack_ratio_mean,
              100 * result.hole_ratio_filled_mean, 100 * result.out_of_view_ratio_mean,
              100 * result.background_ratio_mean, result.ms_per_view, result.sources_loaded,
              result.sources_total, comparison_dir.string().c_str());
  return {{"views", result.views},
          {"psnr_mean", result.psnr_mean},
          {"ssim_mean", result.ssim_mean},
          {"psnr_valid_mean", result.psnr_valid_mean},
          {"hole_ratio_mean", result.hole_ratio_mean},
          {"crack_ratio_mean", result.crack_ratio_mean},
          {"out_of_view_ratio_mean", result.out_of_view_ratio_mean},
          {"background_ratio_mean", result.background_ratio_mean},
          {"hole_ratio_filled_mean", result.hole_ratio_filled_mean},
          {"ms_per_view", result.ms_per_view},
          {"gt_sources", gt_sources},
          {"poses", poses},
          {"poses_registered", registered}};
}

}  // namespace

void RegisterEvaluateCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path workspace;
    std::filesystem::path scene;
    std::filesystem::path json;
    bool no_align = false;
    bool gt_sources = false;
    bool novel_only = false;
    std::string novel_poses = "registered";
    NovelViewSettings settings;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "evaluate", "Measure a workspace against a scene folder's ground truth: camera poses "
                  "after a robust similarity alignment (Ceres) and, when the workspace has "
                  "depth/, its depth maps in the ground-truth cameras.");
  command->add_option("workspace", arguments->workspace, "workspace made by reconstruct")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--gt", arguments->scene, "scene folder with ground truth (gt/sparse)")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--json", arguments->json,
                      "where to write the JSON (default <workspace>/evaluation.json)");
  command->add_flag("--no-align", arguments->no_align,
                    "compare depth without the estimated alignment (identity): for workspaces "
                    "made with reconstruct --known-cameras, whose frame is the ground truth's");
  command->add_flag("--gt-sources", arguments->gt_sources,
                    "render the novel views from the scene's ground-truth cameras and depth "
                    "instead of the workspace's: measures the warp apart from the depth estimate");
  command->add_flag("--novel-only", arguments->novel_only,
                    "evaluate the novel views only (with --gt-sources the workspace only "
                    "receives the comparison images)");
  command->add_option("--novel-poses", arguments->novel_poses,
                      "workspace sources: the novel cameras' poses from registering their photos "
                      "into the SfM model with colmap image_registrator (registered, default; the "
                      "photos give poses only) or from the ground truth through the pose "
                      "alignment (aligned)")
      ->check(CLI::IsMember({"registered", "aligned"}, CLI::ignore_case));
  AddRenderOptions(*command, arguments->settings);
  command->callback([arguments] {
    arguments->settings.Resolve();
    const SceneFolder scene{arguments->scene};

    const std::filesystem::path estimate_dir = arguments->workspace / "sparse";
    if (!DetectSparseFormat(estimate_dir)) {
      throw BadInputError(estimate_dir.string() + " holds no COLMAP model: run parallax "
                          "reconstruct first");
    }
    const SparseModel estimate = ReadSparseModel(estimate_dir);
    const SparseModel truth = ReadSparseModel(scene.Training().sparse);
    const PoseEvaluation evaluation = EvaluatePoses(estimate, truth);
    PrintPoseTable(evaluation);
    nlohmann::json json = nlohmann::json::object();
    AddPoseSections(evaluation, json);

    const std::filesystem::path depth_dir = arguments->workspace / "depth";
    if (HasDepthMaps(depth_dir) && !arguments->novel_only) {
      const std::filesystem::path error_image_dir =
          arguments->workspace / "evaluation" / "depth_error";
      const Similarity3d truth_from_estimate =
          arguments->no_align ? Similarity3d{} : evaluation.alignment.target_from_source;
      const DepthEvaluation depth = EvaluateDepth(estimate, depth_dir, truth,
                                                  scene.Training().depth, truth_from_estimate,
                                                  error_image_dir);
      if (depth.views > 0) {
        PrintDepthSummary(depth, !arguments->no_align, error_image_dir);
        AddDepthSection(depth, json);
      } else {
        std::printf("depth: no depth map in %s belongs to a ground-truth image\n",
                    depth_dir.string().c_str());
      }
    }
    const std::filesystem::path fused = arguments->workspace / "fused.ply";
    if (std::filesystem::exists(fused) && !arguments->novel_only) {
      const CloudAccuracy cloud = MeasureCloud(
          ReadPly(fused).vertices, truth, scene.Training().depth,
          arguments->no_align ? Similarity3d{} : evaluation.alignment.target_from_source);
      std::printf("fused cloud: %zu points, %zu on ground-truth surfaces; median relative "
                  "distance %.3f%%, within 1%% %.1f%%\n",
                  cloud.points, cloud.measured, 100 * cloud.median_relative_distance,
                  100 * cloud.within_1pct);
      json["fused"] = {{"points", cloud.points},
                       {"measured", cloud.measured},
                       {"median_relative_distance", cloud.median_relative_distance},
                       {"within_1pct", cloud.within_1pct}};
    }
    const std::filesystem::path mesh_obj = arguments->workspace / "mesh" / "mesh.obj";
    if (std::filesystem::exists(mesh_obj) && !arguments->novel_only) {
      json["mesh"] = EvaluateMesh(mesh_obj, estimate, arguments->workspace, truth, scene,
                                  arguments->no_align ? Similarity3d{}
                                                      : evaluation.alignment.target_from_source);
    }
    if (std::filesystem::is_directory(scene.Novel().sparse) &&
        (arguments->gt_sources || HasDepthMaps(depth_dir))) {
      json["novel"] = EvaluateNovel(
          scene, arguments->workspace, arguments->gt_sources,
          arguments->novel_poses == "registered",
          arguments->no_align ? Similarity3d{} : evaluation.alignment.target_from_source,
          arguments->settings);
    }
    const nlohmann::json timings = ReconstructTimings(arguments->workspace);
    if (!timings.is_null()) json["timings_s"] = timings;
    const std::filesystem::path out =
        arguments->json.empty() ? arguments->workspace / "evaluation.json" : arguments->json;
    WriteFileAtomically(out, json.dump(2) + "\n");
    std::printf("json: %s\n", out.string().c_str());
  });
}

}  // namespace parallax

#include <cstdio>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/novel_view_options.h"
#include "apps/terminal_progress.h"
#include "core/atomic_file.h"
#include "core/workspace_lock.h"
#include "eval/workspace_evaluation.h"
#include "pipeline/dense_stages.h"

namespace parallax {
namespace {

// Each image's rotation and centre error, a row each under `heading`.
void PrintPoseErrorRows(const char* heading, const std::vector<ImagePoseError>& errors) {
  std::printf("%-24s %14s %16s\n", heading, "rotation (deg)", "centre (% extent)");
  for (const ImagePoseError& image : errors) {
    std::printf("%-24s %14.4f %16.4f\n", image.name.c_str(), image.rotation_error_deg,
                100 * image.center_error_rel);
  }
}

void PrintPoses(const PoseEvaluation& evaluation) {
  PrintPoseErrorRows("image", evaluation.images);
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

void PrintDepth(const WorkspaceEvaluation& evaluation, const Workspace& workspace) {
  if (evaluation.depth_without_truth) {
    std::printf("depth: no depth map in %s belongs to a ground-truth image\n",
                workspace.DepthDir().string().c_str());
  }
  if (!evaluation.depth) return;
  const DepthEvaluation& depth = *evaluation.depth;
  std::printf("depth: %d views (%s); abs_rel median %.3f%%, signed median %+.3f%%; "
              "within 1%% %.1f%%, within 2%% %.1f%%; completeness %.1f%%; error images %s\n",
              depth.views, evaluation.depth_aligned ? "aligned" : "identity alignment",
              100 * depth.abs_rel_median, 100 * depth.signed_median, 100 * depth.within_1pct,
              100 * depth.within_2pct, 100 * depth.completeness,
              evaluation.depth_error_dir.string().c_str());
}

void PrintCloudAndMesh(const WorkspaceEvaluation& evaluation) {
  if (evaluation.fused) {
    const CloudAccuracy& cloud = *evaluation.fused;
    std::printf("fused cloud: %zu points, %zu on ground-truth surfaces; median relative "
                "distance %.3f%%, within 1%% %.1f%%\n",
                cloud.points, cloud.measured, 100 * cloud.median_relative_distance,
                100 * cloud.within_1pct);
  }
  if (evaluation.mesh) {
    const MeshEvaluation& mesh = *evaluation.mesh;
    std::printf("mesh: %zu triangles", mesh.triangles);
    if (mesh.accuracy) {
      std::printf("; vertices: median relative distance %.3f%%, within 1%% %.1f%%",
                  100 * mesh.accuracy->median_relative_distance, 100 * mesh.accuracy->within_1pct);
    }
    std::printf("; textured renders: %.2f dB PSNR on %.1f%% covered pixels (%s)\n",
                mesh.texture.psnr_mean, 100 * mesh.texture.coverage_mean, mesh.render_dir.string().c_str());
  }
  for (const std::string& line : evaluation.not_scored) std::printf("not scored: %s\n", line.c_str());
}

// Each view's loss budget: its pixels by kind (share, PSNR, dB the frame loses to them), and
// how far its covered pixels sit from the photo's (flow median and 90th percentile).
void PrintBudgets(const NovelEvaluation& result) {
  std::printf("%-16s %21s %21s %21s %9s %13s\n", "loss budget", "covered", "background (sky)", "filled",
              "exposure", "misaligned px");
  std::printf("%-16s %21s %21s %21s %9s %13s\n", "", "share  PSNR  lost", "share  PSNR  lost",
              "share  PSNR  lost", "dB", "median    p90");
  const auto row = [](const std::string& name, const LossBudget& budget) {
    std::printf("%-16s", name.c_str());
    for (const PixelShareLoss* part : {&budget.covered, &budget.background, &budget.filled}) {
      std::printf(" %5.1f%% %5.2f %6.2f", 100 * part->share, part->psnr, part->db_lost);
    }
    std::printf(" %+9.2f %6.2f %6.2f\n", budget.exposure_db, budget.misalignment.median_px,
                budget.misalignment.p90_px);
  };
  for (const NovelViewScore& view : result.per_view) row(view.name, view.budget);
  row("mean", result.budget_mean);
}

// How far each registered photo landed from its true pose (through the training cameras'
// alignment), beside the misalignment its render shows.
void PrintRegisteredPoseErrors(const std::vector<ImagePoseError>& errors) {
  if (errors.empty()) return;
  double rotation_mean = 0;
  double center_mean = 0;
  PrintPoseErrorRows("registered pose", errors);
  for (const ImagePoseError& error : errors) {
    rotation_mean += error.rotation_error_deg / static_cast<double>(errors.size());
    center_mean += error.center_error_rel / static_cast<double>(errors.size());
  }
  std::printf("registered poses against the truth: rotation error mean %.4f deg, centre error mean %.4f%%\n",
              rotation_mean, 100 * center_mean);
}

void PrintNovel(const NovelViewsEvaluation& novel) {
  const NovelEvaluation& result = novel.result;
  if (novel.registration_tried) {
    std::printf("novel camera poses: %s\n", novel.registration_note.c_str());
  }
  PrintRegisteredPoseErrors(novel.registered_pose_errors);
  if (!novel.gt_sources) std::printf("novel views: depth holes %s\n", novel.depth_holes_note.c_str());
  std::printf("%-16s %9s %7s %14s %16s %7s\n", "novel view", "PSNR (dB)", "SSIM", "sampled (dB)",
              "exposure (dB)", "holes");
  for (const NovelViewScore& view : result.per_view) {
    std::printf("%-16s %9.2f %7.3f %14.2f %16.2f %6.2f%%\n", view.name.c_str(), view.psnr, view.ssim,
                view.psnr_valid, view.psnr_exposure_matched, 100 * view.hole_ratio);
  }
  PrintBudgets(result);
  std::printf("novel views (%s%s): %d views; PSNR %.2f dB (%.2f dB on sampled pixels, %.2f dB exposure "
              "matched), SSIM %.3f; "
              "holes %.2f%% (cracks %.2f%%) -> %.2f%% after filling; out of view %.2f%%, "
              "background %.2f%%; %.1f ms per view; %d of %d sources loaded (%s)\n",
              novel.gt_sources ? "ground-truth sources" : "workspace sources",
              novel.color_gains ? ", color gains" : "", result.views,
              result.psnr_mean, result.psnr_valid_mean, result.psnr_exposure_matched_mean, result.ssim_mean,
              100 * result.hole_ratio_mean, 100 * result.crack_ratio_mean,
              100 * result.hole_ratio_filled_mean, 100 * result.out_of_view_ratio_mean,
              100 * result.background_ratio_mean, result.ms_per_view, result.sources_loaded,
              result.sources_total, novel.comparison_dir.string().c_str());
}

// The textured mesh at the held-out cameras: whole frames (missed pixels black), the pixels it
// covers, and those another run's mesh covers too.
void PrintMeshHeldOut(const TexturedMeshScore& mesh, const std::filesystem::path& dir, bool common) {
  std::printf("%-16s %9s %7s %14s %9s", "textured mesh", "PSNR (dB)", "SSIM", "covered (dB)", "covered");
  if (common) std::printf(" %17s %7s", "both cover (dB)", "share");
  std::printf("\n");
  for (const TexturedMeshView& view : mesh.per_view) {
    std::printf("%-16s %9.2f %7.3f %14.2f %8.1f%%", view.name.c_str(), view.psnr, view.ssim, view.psnr_covered,
                100 * view.coverage);
    if (common) std::printf(" %17.2f %6.1f%%", view.psnr_common, 100 * view.common_share);
    std::printf("\n");
  }
  std::printf("textured mesh at the held-out cameras: PSNR %.2f dB, SSIM %.3f (whole frames); %.2f dB on the "
              "%.1f%% it covers",
              mesh.frame_psnr_mean, mesh.frame_ssim_mean, mesh.psnr_mean, 100 * mesh.coverage_mean);
  if (common) {
    std::printf("; %.2f dB on the %.1f%% both meshes cover", mesh.common_psnr_mean, 100 * mesh.common_share_mean);
  }
  std::printf(" (%s)\n", dir.string().c_str());
}

struct EvaluateArguments {
  std::filesystem::path workspace;
  std::filesystem::path scene;
  std::filesystem::path json;
  bool no_align = false;
  EvaluateOptions options;
};

// Evaluates under the workspace's exclusive lock, prints each part and writes the JSON.
void RunEvaluate(EvaluateArguments& arguments) {
  arguments.options.align = !arguments.no_align;
  arguments.options.novel.Resolve();
  const Workspace workspace(arguments.workspace);
  // It writes evaluation/ (and missing color gains) into the workspace.
  const WorkspaceLock lock(workspace.Root(), LockMode::kExclusive, "evaluate");
  WorkspaceEvaluation evaluation;
  if (arguments.options.novel.color_gains && !arguments.options.gt_sources) {
    const std::string note = EnsureColorGains(workspace);
    if (!note.empty()) std::printf("%s\n", note.c_str());
  }
  {
    TerminalProgress progress;
    evaluation = arguments.scene.empty()
                     ? EvaluateHeldOut(workspace, arguments.options)
                     : EvaluateWorkspace(workspace, SceneFolder{arguments.scene}, arguments.options, progress);
  }
  if (!evaluation.held_out) PrintPoses(evaluation.poses);
  PrintDepth(evaluation, workspace);
  PrintCloudAndMesh(evaluation);
  if (evaluation.novel) PrintNovel(*evaluation.novel);
  if (evaluation.mesh_held_out) {
    PrintMeshHeldOut(*evaluation.mesh_held_out, evaluation.mesh_held_out_dir,
                     !arguments.options.mesh_common_with.empty());
  }
  const std::filesystem::path out =
      arguments.json.empty() ? EvaluationLayout(workspace.Root()).Json() : arguments.json;
  WriteFileAtomically(out, nlohmann::json(evaluation).dump(2) + "\n");
  std::printf("json: %s\n", out.string().c_str());
}

}  // namespace

void RegisterEvaluateCommand(CLI::App& app) {
  auto arguments = std::make_shared<EvaluateArguments>();
  CLI::App* command = app.add_subcommand(
      "evaluate", "Measure a workspace against a scene folder's ground truth (--gt): camera poses "
                  "after a robust similarity alignment (Ceres), depth maps, cloud and mesh where the "
                  "scene has depth, and its held-out views. Without --gt: the photos reconstruct held "
                  "out (--hold-out) rendered at their cameras and compared with them.");
  command->add_option("workspace", arguments->workspace, "workspace made by reconstruct")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--gt", arguments->scene,
                      "scene folder with ground truth (gt/sparse); without it, the workspace's held-out photos "
                      "are scored")
      ->check(CLI::ExistingDirectory);
  command->add_option("--json", arguments->json,
                      "where to write the JSON (default <workspace>/evaluation.json)");
  command->add_flag("--no-align", arguments->no_align,
                    "compare depth without the estimated alignment (identity): for workspaces "
                    "made with reconstruct --known-cameras, whose frame is the ground truth's");
  command->add_flag("--gt-sources", arguments->options.gt_sources,
                    "render the novel views from the scene's ground-truth cameras and depth "
                    "instead of the workspace's: measures the warp apart from the depth estimate");
  command->add_flag("--novel-only", arguments->options.novel_only,
                    "evaluate the novel views only (with --gt-sources the workspace only "
                    "receives the comparison images)");
  const std::map<std::string, NovelPoses> novel_poses = {{"registered", NovelPoses::kRegistered},
                                                         {"aligned", NovelPoses::kAligned}};
  command->add_option("--novel-poses", arguments->options.novel_poses,
                      "workspace sources: the novel cameras' poses from registering their photos "
                      "into the SfM model with colmap image_registrator (registered, default; the "
                      "photos give poses only) or from the ground truth through the pose "
                      "alignment (aligned)")
      ->transform(CLI::CheckedTransformer(novel_poses, CLI::ignore_case));
  command->add_option("--mesh-common-with", arguments->options.mesh_common_with,
                      "another workspace evaluated at the same held-out photos (a baseline's): also score "
                      "the textured mesh on the pixels both meshes cover")
      ->check(CLI::ExistingDirectory);
  command->add_option("--mesh", arguments->options.mesh,
                      "score this textured mesh instead of the workspace's: an OBJ, or a PLY with per-face "
                      "texcoord and one texture (OpenMVS's TextureMesh --export-type ply); its texture "
                      "is taken as the photos' own colors (no color gains). bench/openmvs-mesh uses it")
      ->check(CLI::ExistingFile);
  AddNovelViewOptions(*command, arguments->options.novel);
  command->callback([arguments] { RunEvaluate(*arguments); });
}

}  // namespace parallax

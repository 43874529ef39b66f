#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "pipeline/evaluate.h"

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

}  // namespace

void RegisterEvaluateCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path workspace;
    std::filesystem::path scene;
    std::filesystem::path json;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "evaluate", "Measure a workspace against a scene folder's ground truth: camera poses "
                  "after a robust similarity alignment (Ceres).");
  command->add_option("workspace", arguments->workspace, "workspace made by reconstruct")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--gt", arguments->scene, "scene folder with ground truth (gt/sparse)")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--json", arguments->json,
                      "where to write the JSON (default <workspace>/evaluation.json)");
  command->callback([arguments] {
    const SceneFolder scene{arguments->scene};
    const std::filesystem::path estimate_dir = arguments->workspace / "sparse";
    if (!DetectSparseFormat(estimate_dir)) {
      throw BadInputError(estimate_dir.string() + " holds no COLMAP model: run parallax "
                          "reconstruct first");
    }
    const PoseEvaluation evaluation =
        EvaluatePoses(ReadSparseModel(estimate_dir), ReadSparseModel(scene.Training().sparse));
    PrintPoseTable(evaluation);
    nlohmann::json json = nlohmann::json::object();
    AddPoseSections(evaluation, json);
    const nlohmann::json timings = ReconstructTimings(arguments->workspace);
    if (!timings.is_null()) json["timings_s"] = timings;
    const std::filesystem::path out =
        arguments->json.empty() ? arguments->workspace / "evaluation.json" : arguments->json;
    WriteFileAtomically(out, json.dump(2) + "\n");
    std::printf("json: %s\n", out.string().c_str());
  });
}

}  // namespace parallax

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.h"
#include "apps/novel_view_options.h"
#include "apps/slurm_cli.h"
#include "apps/terminal_progress.h"
#include "pipeline/render_request.h"

namespace parallax {

namespace {

struct RenderArguments {
  std::filesystem::path input;
  std::filesystem::path cameras;
  std::string path;
  std::filesystem::path out;
  NovelViewSettings settings;
  SlurmCli slurm;
  RenderPart part;
};

void PrintRenderSummary(const RenderSummary& summary, const RenderArguments& arguments) {
  if (arguments.part.step != RenderStep::kAll) {
    for (const RequestStage& stage : summary.stages) {
      std::printf("render %s: %s\n", stage.name.c_str(), stage.reason.c_str());
    }
    return;
  }
  if (!summary.depth_note.empty()) std::printf("depth: %s\n", summary.depth_note.c_str());
  for (const std::string& name : summary.dropped) {
    std::fprintf(stderr, "render: %s has no depth map (none could be estimated); not used\n", name.c_str());
  }
  std::printf("rendered %zu views from %d of %zu source views (the others were never loaded); "
              "mean hole ratio %.2f%% before filling, %.2f%% after; %.1f ms per view -> %s\n",
              summary.views, summary.sources_loaded, summary.source_views, 100 * summary.hole_ratio_mean,
              100 * summary.hole_ratio_filled_mean, summary.ms_per_view, arguments.out.string().c_str());
}

// The cameras as the command line names them; submitted to Slurm or rendered here.
void RunRender(RenderArguments& arguments, const CLI::App& command) {
  arguments.settings.Resolve();
  if (arguments.cameras.empty() && arguments.path.empty()) {
    throw CLI::ValidationError("render", "give the cameras: --cameras <model_dir> or --path <spec>");
  }
  const RenderTargets targets{arguments.cameras, arguments.path.empty()
                                                     ? std::nullopt
                                                     : std::optional(ParseCameraPath(arguments.path))};
  if (arguments.slurm.OnSlurm()) {
    const SlurmOptions slurm = arguments.slurm.Resolve();
    const SlurmSubmission submission = SubmitRenderToSlurm(
        arguments.out, CountRenderTargets(arguments.input, targets), ThisExecutable(),
        JobArguments(command, {arguments.input}, {"--out", "--cameras"}), slurm);
    PrintSubmission(submission, slurm.wait);
    return;
  }
  const auto print_view = [](size_t i, size_t count, const NamedCamera& target, const NovelView& view) {
    std::fprintf(stderr, "render %zu/%zu %s: %zu sources, holes %.2f%% -> %.2f%% filled, %.0f ms\n", i + 1, count,
                 target.name.c_str(), view.sources.size(), 100 * view.result.metrics.hole_ratio,
                 100 * view.result.fill.hole_ratio_filled, view.ms);
  };
  RenderSummary summary;
  {
    TerminalProgress progress;
    summary = RenderCameras(arguments.input, targets, arguments.settings, arguments.out, progress, print_view,
                            arguments.part);
  }
  PrintRenderSummary(summary, arguments);
}

}  // namespace

void RegisterRenderCommand(CLI::App& app) {
  auto arguments = std::make_shared<RenderArguments>();
  CLI::App* command = app.add_subcommand(
      "render",
      "Render novel viewpoints by depth-image-based warping from the photos and depth maps of "
      "a workspace (its SfM frame) or a scene folder (its ground-truth cameras and depth). "
      "Writes <name>.png, <name>.holes.png, <name>.depth.exr, render.csv and report.json (what was "
      "computed and what was left out, and why).");
  command->add_option("input", arguments->input, "workspace or scene folder")->required();
  auto* cameras = command->add_option(
      "--cameras", arguments->cameras,
      "COLMAP model (text or binary) of the cameras to render, in the input's frame");
  auto* path = command->add_option(
      "--path", arguments->path,
      "camera path: orbit:N (N views around the scene, or along the arc the photos were taken from "
      "when they leave a quarter of the circle out), photos:N (N views along a smooth curve through "
      "every photo camera) or between:IMAGE_A,IMAGE_B,N");
  cameras->excludes(path);
  path->excludes(cameras);
  command->add_option("--out", arguments->out, "output folder (created if missing)")->required();
  AddNovelViewOptions(*command, arguments->settings);
  AddSlurmOptions(*command, arguments->slurm, "the frames as a job array (then one job collects render.csv)",
                  "frames per task");
  // The jobs' steps (pipeline/render_request.h RenderStep); not for people.
  const std::map<std::string, RenderStep> steps = {
      {"prepare", RenderStep::kPrepare}, {"frames", RenderStep::kFrames}, {"collect", RenderStep::kCollect}};
  command->add_option("--job-step", arguments->part.step)
      ->transform(CLI::CheckedTransformer(steps))
      ->group("");
  command->add_option("--block", arguments->part.block)->check(CLI::NonNegativeNumber)->group("");
  command->add_option("--block-size", arguments->part.block_size)->check(CLI::PositiveNumber)->group("");
  command->callback([arguments, command] { RunRender(*arguments, *command); });
}

}  // namespace parallax

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "apps/render_options.h"
#include "apps/terminal_progress.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "pipeline/mvs.h"
#include "reproject/novel_views.h"

namespace parallax {
namespace {

std::string CsvRow(const std::string& name, const NovelView& view) {
  const HoleMetrics& m = view.result.metrics;
  std::string sources;
  for (const std::string& source : view.sources) sources += (sources.empty() ? "" : " ") + source;
  const std::string fill = view.result.fill.skipped.empty() ? "ran" : "skipped: " + view.result.fill.skipped;
  char numbers[256];
  std::snprintf(numbers, sizeof(numbers), ",%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%d,",
                m.hole_ratio, view.result.fill.hole_ratio_filled, m.crack_ratio,
                m.disocclusion_ratio, m.out_of_view_ratio, m.background_ratio, m.hole_count,
                m.largest_hole_px);
  char ms[32];
  std::snprintf(ms, sizeof(ms), ",%.2f\n", view.ms);
  // Names and the fill's reason can be long: no fixed-size buffer for them.
  return name + "," + sources + numbers + fill + ms;
}

// A stage of the request, as report.json lists it: run, or skipped and why.
nlohmann::json Stage(const std::string& name, const std::string& skipped_because, const std::string& done = "") {
  nlohmann::json stage = {{"name", name}, {"skipped", !skipped_because.empty()}};
  stage["reason"] = skipped_because.empty() ? done : skipped_because;
  return stage;
}

// A workspace made with `reconstruct --no-depth` (or missing some depth maps) gets depth for
// the source views the targets use, and for no other view. Returns the names estimated.
std::vector<std::string> EstimateMissingDepth(const std::filesystem::path& workspace,
                                              const SourceLibrary& library,
                                              const std::vector<NamedCamera>& targets,
                                              const SourceSelectionOptions& selection) {
  std::set<std::string> missing;
  for (const NamedCamera& target : targets) {
    for (int index : SelectSources(library.Cameras(), target.camera, selection)) {
      const std::string& name = library.Names()[static_cast<size_t>(index)];
      const auto stem = std::filesystem::path(name).stem().string();
      if (!std::filesystem::exists(workspace / "depth" / (stem + ".exr"))) missing.insert(name);
    }
  }
  if (missing.empty()) return {};
  MvsOptions options = MvsOptionsFor(Quality::kBalanced);
  options.only_views.assign(missing.begin(), missing.end());
  MvsSummary summary;
  {
    TerminalProgress progress;
    summary = RunMultiViewStereo(workspace, options, progress);
  }
  std::printf("depth: estimated %zu of %zu views (PatchMatch on %d, for the geometric check); "
              "the other views are not needed by these cameras\n",
              summary.views.size(), library.Cameras().size(), summary.estimated_views);
  return options.only_views;
}

}  // namespace

void RegisterRenderCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path input;
    std::filesystem::path cameras;
    std::string path;
    std::filesystem::path out;
    NovelViewSettings settings;
  };
  auto arguments = std::make_shared<Arguments>();
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
      "camera path: orbit:N (N views around the scene) or between:IMAGE_A,IMAGE_B,N");
  cameras->excludes(path);
  path->excludes(cameras);
  command->add_option("--out", arguments->out, "output folder (created if missing)")->required();
  AddRenderOptions(*command, arguments->settings);
  command->callback([arguments] {
    arguments->settings.Resolve();
    const SourceSelectionOptions& selection = arguments->settings.selection;
    const RenderOptions& render_options = arguments->settings.render;
    if (arguments->cameras.empty() && arguments->path.empty()) {
      throw CLI::ValidationError("render", "give the cameras: --cameras <model_dir> or --path <spec>");
    }
    SourceLibrary library(SourcePathsFor(arguments->input));
    const std::vector<NamedCamera> targets =
        arguments->cameras.empty()
            ? CamerasAlongPath(arguments->path, library.Cameras(), library.Names())
            : CamerasFromModel(arguments->cameras);
    const size_t all_views = library.Cameras().size();
    nlohmann::json stages = nlohmann::json::array();
    const bool scene_folder = std::filesystem::is_directory(arguments->input / "gt");
    if (scene_folder) {
      stages.push_back(Stage("depth", "a scene folder: its ground-truth depth maps are used"));
    } else {
      const std::vector<std::string> estimated = EstimateMissingDepth(arguments->input, library, targets, selection);
      stages.push_back(estimated.empty()
                           ? Stage("depth", "every source view these cameras use already has a depth map")
                           : Stage("depth", "", "estimated for " + std::to_string(estimated.size()) + " of " +
                                                    std::to_string(all_views) +
                                                    " views: those these cameras use and had none"));
    }
    // What `reconstruct` would also make, and a request for novel views alone does not need.
    stages.push_back(Stage("fusion", "novel views warp each source's depth map; no fused cloud is needed"));
    stages.push_back(Stage("mesh", "only novel views are requested: building the Poisson mesh and its "
                                   "texture atlas for them would cost more than the holes it fills "
                                   "(one that reconstruct made is used, see depth_holes)"));
    for (const std::string& name : library.DropViewsWithoutDepth()) {
      std::fprintf(stderr, "render: %s has no depth map (none could be estimated); not used\n",
                   name.c_str());
    }
    const WorkspaceDepthPreparation depth_holes =
        scene_folder ? WorkspaceDepthPreparation{}
                     : PrepareWorkspaceDepth(arguments->input, arguments->settings, &library);
    std::string csv =
        "name,sources,hole_ratio,hole_ratio_filled,crack_ratio,disocclusion_ratio,"
        "out_of_view_ratio,background_ratio,holes,largest_hole_px,fill,ms\n";
    double hole_sum = 0, filled_sum = 0, ms_sum = 0;
    std::map<std::string, size_t> fill_skipped;  // Views by the reason their fill was skipped.
    Renderer renderer(render_options);
    NovelView view;
    for (size_t i = 0; i < targets.size(); ++i) {
      RenderNovelView(library, targets[i], selection, renderer, &view);
      WriteNovelView(arguments->out, targets[i].name, view.result);
      csv += CsvRow(targets[i].name, view);
      hole_sum += view.result.metrics.hole_ratio;
      filled_sum += view.result.fill.hole_ratio_filled;
      ms_sum += view.ms;
      if (!view.result.fill.skipped.empty()) ++fill_skipped[view.result.fill.skipped];
      std::fprintf(stderr, "render %zu/%zu %s: %zu sources, holes %.2f%% -> %.2f%% filled, %.0f ms\n",
                   i + 1, targets.size(), targets[i].name.c_str(), view.sources.size(),
                   100 * view.result.metrics.hole_ratio, 100 * view.result.fill.hole_ratio_filled,
                   view.ms);
    }
    WriteFileAtomically(arguments->out / "render.csv", csv);
    stages.push_back(Stage("sources", "", "loaded " + std::to_string(library.LoadedCount()) + " of " +
                                              std::to_string(all_views) +
                                              " source views: the others can not contribute to these cameras"));
    if (scene_folder) {
      stages.push_back(Stage("depth_holes", "ground-truth depth has no holes"));
    } else if (library.LoadedPixels() > 0 && depth_holes.mesh) {
      char share[32];
      std::snprintf(share, sizeof share, "%.2f%%",
                    100.0 * static_cast<double>(library.PreparedPixels()) /
                        static_cast<double>(library.LoadedPixels()));
      stages.push_back(Stage("depth_holes", "", "filled " + std::string(share) +
                                                    " of the loaded sources' pixels " + depth_holes.note));
    } else {
      stages.push_back(Stage("depth_holes", depth_holes.note));
    }
    std::string fill_skips;
    size_t skipped_views = 0;
    for (const auto& [reason, count] : fill_skipped) {
      fill_skips += "; skipped for " + std::to_string(count) + ": " + reason;
      skipped_views += count;
    }
    const bool none_filled = !fill_skipped.empty() && skipped_views == targets.size();
    stages.push_back(Stage("fill", none_filled ? fill_skips.substr(2) : "",
                           "ran for " + std::to_string(targets.size() - skipped_views) + " of " +
                               std::to_string(targets.size()) + " views" + fill_skips));
    WriteFileAtomically(arguments->out / "report.json", nlohmann::json({{"render", {{"stages", stages}}}}).dump(2) + "\n");
    const double n = static_cast<double>(targets.size());
    std::printf("rendered %zu views from %d of %zu source views (the others were never loaded); "
                "mean hole ratio %.2f%% before filling, %.2f%% after; %.1f ms per view -> %s\n",
                targets.size(), library.LoadedCount(), all_views,
                100 * hole_sum / n, 100 * filled_sum / n, ms_sum / n, arguments->out.string().c_str());
  });
}

}  // namespace parallax

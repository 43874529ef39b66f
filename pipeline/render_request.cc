#include "pipeline/render_request.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/workspace.h"
#include "core/workspace_lock.h"
#include "mvs/mvs.h"
#include "pipeline/dense_stages.h"
#include "pipeline/stage_graph.h"
#include "reproject/distorted_target.h"

namespace parallax {
namespace fs = std::filesystem;
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

RequestStage Ran(const std::string& name, const std::string& what) { return {name, false, what}; }
RequestStage Skipped(const std::string& name, const std::string& why) { return {name, true, why}; }

// A workspace made with `reconstruct --no-depth` (or missing some depth maps) gets depth for
// the source views the targets use, and for no other view.
void EstimateMissingDepth(const Workspace& workspace, const SourceLibrary& library,
                          const std::vector<NamedCamera>& targets,
                          const SourceSelectionOptions& selection, WorkspaceLock& lock, Progress& progress,
                          RenderSummary& summary) {
  std::set<std::string> missing;
  for (const NamedCamera& target : targets) {
    for (int index : SelectSources(library.Cameras(), RenderedCamera(target.camera), selection)) {
      const std::string& name = library.Names()[static_cast<size_t>(index)];
      if (!fs::exists(workspace.Depth(name))) missing.insert(name);
    }
  }
  if (missing.empty()) {
    summary.stages.push_back(Skipped("depth", "every source view these cameras use already has a depth map"));
    return;
  }
  // The depth stage of the workspace's graph, for these views: recorded in stages.json like
  // reconstruct's, at reconstruct's default quality.
  lock.MakeExclusive();
  StageGraph graph(workspace, false);
  if (!graph.CacheDamage().empty()) progress.Warn(graph.CacheDamage());
  DepthRequest request;
  request.views.assign(missing.begin(), missing.end());
  MvsSummary mvs;
  graph.Run(DepthStage(workspace, UndistortedModelKey(workspace, graph), request, progress, &mvs));
  char note[256];
  std::snprintf(note, sizeof(note),
                "estimated %zu of %zu views (PatchMatch on %d, for the geometric check); the "
                "other views are not needed by these cameras",
                mvs.views.size(), library.Cameras().size(), mvs.estimated_views);
  summary.depth_note = note;
  summary.depth_estimated = request.views;
  summary.stages.push_back(Ran("depth", "estimated for " + std::to_string(missing.size()) + " of " +
                                            std::to_string(library.Cameras().size()) +
                                            " views: those these cameras use and had none"));
}

// The workspace's color gains, estimated through its graph when a workspace made before they
// existed lacks them.
RequestStage ColorGainsStep(const fs::path& input, bool scene_folder, bool wanted, WorkspaceLock* lock) {
  if (scene_folder) return Skipped("color_gains", "a scene folder: its photos are used as they are");
  if (!wanted) return Skipped("color_gains", "--no-color-gains: photos blended as they are");
  const Workspace workspace(input);
  if (!fs::exists(workspace.ColorGainsFile())) lock->MakeExclusive();
  const std::string note = EnsureColorGains(workspace);
  if (note.empty()) return Skipped("color_gains", "already estimated: " + workspace.ColorGainsFile().string());
  return Ran("color_gains", note);
}

RequestStage DepthHolesStage(bool scene_folder, const SourceLibrary& library,
                             const WorkspaceDepthPreparation& depth_holes) {
  if (scene_folder) return Skipped("depth_holes", "ground-truth depth has no holes");
  if (library.LoadedPixels() == 0 || !depth_holes.mesh) return Skipped("depth_holes", depth_holes.note);
  char share[32];
  std::snprintf(share, sizeof share, "%.2f%%",
                100.0 * static_cast<double>(library.PreparedPixels()) /
                    static_cast<double>(library.LoadedPixels()));
  return Ran("depth_holes", "filled " + std::string(share) + " of the loaded sources' pixels " +
                                depth_holes.note);
}

// The share of a frame no surface reached (holes and out of view), which the fill made.
double FilledShare(const RenderResult& result) {
  return result.metrics.hole_ratio + result.metrics.out_of_view_ratio;
}

// How much of the frames the fill made: the mean share and the frame with the most.
struct FilledFrames {
  double sum = 0;
  double most = -1;
  std::string most_name;

  void Add(const std::string& name, double share) {
    sum += share;
    if (share > most) most = share, most_name = name;
  }
  std::string Say(size_t views) const {
    if (views == 0) return "";
    char text[160];
    std::snprintf(text, sizeof text, "; %.1f%% of each frame filled on average, most in %s (%.1f%%)",
                  100 * sum / static_cast<double>(views), most_name.c_str(), 100 * most);
    return text;
  }
};

RequestStage FillStage(const std::map<std::string, size_t>& fill_skipped, const FilledFrames& filled,
                       size_t views) {
  std::string fill_skips;
  size_t skipped_views = 0;
  for (const auto& [reason, count] : fill_skipped) {
    fill_skips += "; skipped for " + std::to_string(count) + ": " + reason;
    skipped_views += count;
  }
  const bool none_filled = !fill_skipped.empty() && skipped_views == views;
  const std::string ran = "ran for " + std::to_string(views - skipped_views) + " of " +
                          std::to_string(views) + " views" + filled.Say(views) + fill_skips;
  return none_filled ? Skipped("fill", fill_skips.substr(2)) : Ran("fill", ran);
}

}  // namespace

void to_json(nlohmann::json& json, const RequestStage& stage) {
  json = {{"name", stage.name}, {"skipped", stage.skipped}, {"reason", stage.reason}};
}

namespace {

std::vector<NamedCamera> TargetCameras(const fs::path& input, const RenderTargets& cameras,
                                       const SourceLibrary& library) {
  // A scene folder has neither the mesh nor the cloud: its cameras alone make the frame.
  return cameras.path ? CamerasAlongPath(*cameras.path, Workspace(input).Geometry(), library.Cameras(), library.Names())
                      : CamerasFromModel(cameras.model);
}

constexpr const char* kCsvHeader =
    "name,sources,hole_ratio,hole_ratio_filled,crack_ratio,disocclusion_ratio,"
    "out_of_view_ratio,background_ratio,holes,largest_hole_px,fill,ms\n";

fs::path BlocksFolder(const fs::path& out) { return out / "blocks"; }
fs::path BlockCsv(const fs::path& out, int block) { return BlocksFolder(out) / (std::to_string(block) + ".csv"); }
fs::path BlockReport(const fs::path& out, const std::string& block) { return BlocksFolder(out) / (block + ".json"); }

void WriteStages(const fs::path& file, const std::vector<RequestStage>& stages) {
  WriteFileAtomically(file, nlohmann::json({{"render", {{"stages", stages}}}}).dump(2) + "\n");
}

nlohmann::json ReadBlockReport(const fs::path& file) {
  if (!fs::exists(file)) throw BadInputError(file.string() + " is missing: that block has not run (or failed)");
  try {
    return nlohmann::json::parse(ReadFileBytes(file)).at("render").at("stages");
  } catch (const nlohmann::json::exception& error) {
    throw BadInputError(file.string() + " is not a render block's report: " + error.what());
  }
}

// render.csv and report.json from the blocks the frames were rendered in.
RenderSummary CollectBlocks(const fs::path& out, size_t frames, int block_size) {
  const int blocks = static_cast<int>((frames + block_size - 1) / block_size);
  std::string csv = kCsvHeader;
  nlohmann::json block_stages = nlohmann::json::array();
  for (int block = 0; block < blocks; ++block) {
    block_stages.push_back(ReadBlockReport(BlockReport(out, std::to_string(block))));
    csv += ReadFileBytes(BlockCsv(out, block));
  }
  RenderSummary summary;
  summary.views = frames;
  summary.stages = {Ran("frames", "collected " + std::to_string(frames) + " cameras from " + std::to_string(blocks) +
                                      " blocks of " + std::to_string(block_size) + " (each block's stages under blocks)")};
  nlohmann::json stages = ReadBlockReport(BlockReport(out, "prepare"));
  stages.push_back(summary.stages.front());
  WriteFileAtomically(out / "render.csv", csv);
  WriteFileAtomically(out / "report.json",
                      nlohmann::json({{"render", {{"stages", stages}, {"blocks", block_stages}}}}).dump(2) + "\n");
  return summary;
}

}  // namespace

size_t CountRenderTargets(const fs::path& input, const RenderTargets& targets) {
  const SourceLibrary library(SourcePathsFor(input));
  // An orbit around sources has as many frames as it says: counting them reads no mesh or cloud.
  if (targets.path && targets.path->kind == CameraPath::Kind::kOrbit && !library.Cameras().empty()) {
    return static_cast<size_t>(targets.path->frames);
  }
  return TargetCameras(input, targets, library).size();
}

RenderSummary RenderCameras(const fs::path& input, const RenderTargets& cameras,
                            const NovelViewSettings& settings, const fs::path& out,
                            Progress& progress, const RenderedView& on_view, const RenderPart& part) {
  if (part.step == RenderStep::kCollect) {
    return CollectBlocks(out, CountRenderTargets(input, cameras), part.block_size);
  }
  RenderSummary summary;
  const SceneFolder scene{input};
  const bool scene_folder = fs::is_directory(scene.GroundTruth());
  ViewSetPaths source_paths = SourcePathsFor(input);
  // A workspace is read under a shared lock, and written (missing gains or depth) only alone.
  std::optional<WorkspaceLock> lock;
  if (!scene_folder) lock.emplace(input, LockMode::kShared, "render");
  summary.stages.push_back(ColorGainsStep(input, scene_folder, settings.color_gains, lock ? &*lock : nullptr));
  if (!settings.color_gains) source_paths.color_gains.clear();
  SourceLibrary library(source_paths);
  std::vector<NamedCamera> targets = TargetCameras(input, cameras, library);
  if (part.step == RenderStep::kFrames) {
    const size_t first = std::min(targets.size(), static_cast<size_t>(part.block) * part.block_size);
    const size_t last = std::min(targets.size(), first + part.block_size);
    targets = std::vector<NamedCamera>(targets.begin() + first, targets.begin() + last);
    if (fs::exists(BlockCsv(out, part.block))) {
      summary.stages = {Skipped("frames", "block " + std::to_string(part.block) + " already rendered")};
      return summary;
    }
  }
  summary.source_views = library.Cameras().size();
  if (scene_folder) {
    summary.stages.push_back(Skipped("depth", "a scene folder: its ground-truth depth maps are used"));
  } else {
    EstimateMissingDepth(Workspace(input), library, targets, settings.selection, *lock, progress, summary);
  }
  // What `reconstruct` would also make, and a request for novel views alone does not need.
  summary.stages.push_back(Skipped("fusion", "novel views warp each source's depth map; no fused cloud is needed"));
  summary.stages.push_back(Skipped("mesh", "only novel views are requested: building the Poisson mesh and its "
                                           "texture atlas for them would cost more than the holes it fills "
                                           "(one that reconstruct made is used, see depth_holes)"));
  if (part.step == RenderStep::kPrepare) {
    fs::create_directories(BlocksFolder(out));
    WriteStages(BlockReport(out, "prepare"), summary.stages);
    return summary;
  }
  summary.dropped = library.DropViewsWithoutDepth();
  const WorkspaceDepthPreparation depth_holes =
      scene_folder ? WorkspaceDepthPreparation{} : PrepareWorkspaceDepth(Workspace(input).Mesh(), settings, &library);
  std::string csv;
  double hole_sum = 0, filled_sum = 0, ms_sum = 0;
  std::map<std::string, size_t> fill_skipped;  // Views by the reason their fill was skipped.
  FilledFrames filled_frames;
  Renderer renderer(settings.render);
  NovelView view;
  for (size_t i = 0; i < targets.size(); ++i) {
    RenderNovelView(library, targets[i], settings.selection, renderer, &view);
    WriteNovelView(out, targets[i].name, view.result);
    csv += CsvRow(targets[i].name, view);
    hole_sum += view.result.metrics.hole_ratio;
    filled_sum += view.result.fill.hole_ratio_filled;
    ms_sum += view.ms;
    if (!view.result.fill.skipped.empty()) ++fill_skipped[view.result.fill.skipped];
    filled_frames.Add(targets[i].name, FilledShare(view.result));
    if (on_view) on_view(i, targets.size(), targets[i], view);
  }
  summary.sources_loaded = library.LoadedCount();
  summary.stages.push_back(Ran("sources", "loaded " + std::to_string(library.LoadedCount()) + " of " +
                                              std::to_string(summary.source_views) +
                                              " source views: the others can not contribute to these cameras"));
  summary.stages.push_back(DepthHolesStage(scene_folder, library, depth_holes));
  summary.stages.push_back(FillStage(fill_skipped, filled_frames, targets.size()));
  if (part.step == RenderStep::kFrames) {
    // The report first: a block counts as done once its rows are there.
    WriteStages(BlockReport(out, std::to_string(part.block)), summary.stages);
    WriteFileAtomically(BlockCsv(out, part.block), csv);
  } else {
    WriteFileAtomically(out / "render.csv", kCsvHeader + csv);
    WriteStages(out / "report.json", summary.stages);
  }
  const double n = static_cast<double>(std::max<size_t>(1, targets.size()));
  summary.views = targets.size();
  summary.hole_ratio_mean = hole_sum / n;
  summary.hole_ratio_filled_mean = filled_sum / n;
  summary.ms_per_view = ms_sum / n;
  return summary;
}

}  // namespace parallax

#include "pipeline/depth_workspace.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/image.h"
#include "core/sparse_model.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// PlanDepth, its error naming the workspace.
DepthPlan PlanWorkspaceDepth(const Workspace& ws, const SparseModel& model, const MvsOptions& options) {
  try {
    return PlanDepth(model, options);
  } catch (const BadInputError& error) {
    throw BadInputError(ws.Root().string() + ": " + error.what());
  }
}

// The views a reference needs (itself and its sources) at the working resolution; those
// `previous` already holds are moved over, not loaded again, so consecutive references share
// their common sources and no more than one reference's views are in memory.
std::map<uint32_t, StereoView> LoadStereoViews(const Workspace& ws, const SparseModel& model,
                                               const ViewPlan& plan, const MvsOptions& options,
                                               std::map<uint32_t, StereoView>& previous) {
  std::map<uint32_t, StereoView> views;
  std::vector<uint32_t> ids = plan.sources;
  ids.push_back(plan.image_id);
  for (const uint32_t id : ids) {
    if (const auto found = previous.find(id); found != previous.end()) {
      views[id] = std::move(found->second);
      continue;
    }
    const SparseImage& image = model.ImageById(id);
    StereoView& view = views[id];
    view = WorkingStereoView(model, image, options);
    view.image = WorkingGray(ReadImage(ws.Image(image.name)), view.camera);
  }
  previous.clear();
  return views;
}

// A photometric estimate between the passes: depth, normal (3) and cost planes.
void WriteEstimate(const fs::path& path, const DepthNormalMap& estimate) {
  const size_t pixels = estimate.depth.Values().size();
  DenseArray array{estimate.depth.Width(), estimate.depth.Height(), 5, std::vector<float>(5 * pixels)};
  for (size_t i = 0; i < pixels; ++i) {
    array.values[i] = estimate.depth.Values()[i];
    for (size_t c = 0; c < 3; ++c) array.values[(1 + c) * pixels + i] = estimate.normal[3 * i + c];
    array.values[4 * pixels + i] = estimate.cost[i];
  }
  WriteColmapArray(path, array);
}

DepthNormalMap ReadEstimate(const fs::path& path) {
  const DenseArray array = ReadColmapArray(path);
  if (array.channels != 5) throw BadInputError(path.string() + ": not a depth-stage estimate");
  const size_t pixels = static_cast<size_t>(array.width) * static_cast<size_t>(array.height);
  DepthNormalMap estimate{DepthMap(array.width, array.height), std::vector<float>(3 * pixels),
                          std::vector<float>(pixels)};
  for (size_t i = 0; i < pixels; ++i) {
    estimate.depth.Values()[i] = array.values[i];
    for (size_t c = 0; c < 3; ++c) estimate.normal[3 * i + c] = array.values[(1 + c) * pixels + i];
    estimate.cost[i] = array.values[4 * pixels + i];
  }
  return estimate;
}

// PatchMatch on each of `plans` whose estimate is not in <ws>/stereo/estimates yet.
void EstimatePhotometric(const Workspace& ws, const SparseModel& model, const std::vector<ViewPlan>& plans,
                         const MvsOptions& options, Progress& progress) {
  std::map<uint32_t, StereoView> views;
  const auto total = static_cast<int64_t>(plans.size());
  for (size_t i = 0; i < plans.size(); ++i) {
    progress.Update("depth", static_cast<int64_t>(i), total);
    const ViewPlan& plan = plans[i];
    if (fs::exists(ws.StereoEstimate(plan.name))) continue;
    views = LoadStereoViews(ws, model, plan, options, views);
    WriteEstimate(ws.StereoEstimate(plan.name), EstimateViewDepth(plan, views, options));
  }
  progress.Update("depth", total, total);
}

// The view's maps in both formats (COLMAP's under <ws>/stereo, EXR under <ws>/depth), the six
// files made and written side by side.
void WriteViewDepth(const Workspace& ws, const ViewDepth& view) {
  const std::string& name = view.report.name;
  // One pass's COLMAP depth and normal maps, where `kept` has depth.
  const auto write_colmap_pass = [&](StereoPass pass, const DepthMap& kept) {
    tbb::parallel_invoke(
        [&] { WriteColmapDepth(ws.StereoDepthMap(name, pass), ToColmapSampling(kept)); },
        [&] { WriteColmapArray(ws.StereoNormalMap(name, pass), ColmapNormalMap(view.estimate, kept)); });
  };
  tbb::parallel_invoke([&] { write_colmap_pass(StereoPass::kPhotometric, view.estimate.depth); },
                       [&] { write_colmap_pass(StereoPass::kGeometric, view.filtered.depth); },
                       [&] { WriteDepthExr(ws.Depth(name), view.filtered.depth); },
                       [&] { WriteDepthExr(ws.DepthConfidence(name), view.filtered.confidence); });
}

// The geometric pass for one view: its estimate checked against those of its sources in
// `estimated` (read back from <ws>/stereo/estimates), written in both formats.
MvsViewReport FilterAndWriteView(const Workspace& ws, const SparseModel& model, const ViewPlan& view,
                                 const std::set<std::string>& estimated, const MvsOptions& options) {
  // The estimates of the sources that have one, and the view's own (last), read side by side.
  std::vector<uint32_t> ids;
  std::vector<std::string> names;
  for (const uint32_t id : view.sources) {
    if (!estimated.count(model.ImageById(id).name)) continue;
    ids.push_back(id);
    names.push_back(model.ImageById(id).name);
  }
  names.push_back(view.name);
  std::vector<DepthNormalMap> read(names.size());
  tbb::parallel_for(size_t{0}, names.size(), [&](size_t i) { read[i] = ReadEstimate(ws.StereoEstimate(names[i])); });
  std::map<uint32_t, DepthNormalMap> source_estimates;
  for (size_t i = 0; i < ids.size(); ++i) source_estimates[ids[i]] = std::move(read[i]);
  const DepthNormalMap& low = read.back();
  const ViewDepth depth = FilterViewDepth(model, view, low, source_estimates, options);
  WriteViewDepth(ws, depth);
  return depth.report;
}

// The views of the geometric block `in_block` whose report is not written yet, filtered and
// written, each with its report.
void FilterAndWriteBlock(const Workspace& ws, const SparseModel& model, const DepthPlan& plan,
                         const std::vector<ViewPlan>& in_block, const MvsOptions& options, Progress& progress) {
  std::set<std::string> estimated;
  for (const ViewPlan& view : plan.estimated) estimated.insert(view.name);
  const auto total = static_cast<int64_t>(in_block.size());
  for (size_t i = 0; i < in_block.size(); ++i) {
    progress.Update("filter", static_cast<int64_t>(i), total);
    const fs::path report = ws.StereoViewReport(in_block[i].name);
    if (fs::exists(report)) continue;
    const MvsViewReport written = FilterAndWriteView(ws, model, in_block[i], estimated, options);
    WriteFileAtomically(report, nlohmann::json(written).dump() + "\n");
  }
  progress.Update("filter", total, total);
}

// The depth stage key the estimates in <ws>/stereo/estimates were made for.
fs::path EstimatesKeyFile(const Workspace& workspace) { return workspace.StereoEstimates() / "key.txt"; }

// Whether `path` (an estimate, or a view's report) reads back whole.
bool IsWhole(const fs::path& path) {
  try {
    if (path.extension() == ".json") return nlohmann::json::accept(ReadFileBytes(path));
    return ReadColmapArray(path).channels == 5;
  } catch (const BadInputError&) {
    return false;
  }
}

}  // namespace

bool EstimatesMadeFor(const Workspace& workspace, const std::string& key) {
  const fs::path key_file = EstimatesKeyFile(workspace);
  return fs::exists(key_file) && ReadFileBytes(key_file) == key;
}

ResumedViews PrepareEstimates(const Workspace& workspace, const std::string& key) {
  ResumedViews resumed;
  if (!EstimatesMadeFor(workspace, key)) {
    fs::remove_all(workspace.StereoEstimates());
    fs::create_directories(workspace.StereoEstimates());
    WriteFileAtomically(EstimatesKeyFile(workspace), key);
    return resumed;
  }
  for (const auto& entry : fs::directory_iterator(workspace.StereoEstimates())) {
    const fs::path& path = entry.path();
    const bool estimate = path.extension() == ".bin", report = path.extension() == ".json";
    if (!estimate && !report) continue;
    if (!IsWhole(path)) {
      fs::remove(path);
      continue;
    }
    ++(estimate ? resumed.estimates : resumed.filtered);
  }
  return resumed;
}

MvsSummary RunMultiViewStereo(const Workspace& workspace, const MvsOptions& options, const std::string& key,
                              Progress& progress) {
  const ResumedViews resumed = PrepareEstimates(workspace, key);
  auto start = std::chrono::steady_clock::now();
  RunMultiViewStereoBlock(workspace, options, {MvsPass::kPhotometric}, progress);
  const double photometric_seconds = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  RunMultiViewStereoBlock(workspace, options, {MvsPass::kGeometric}, progress);
  MvsSummary summary = FinishMultiViewStereoBlocks(workspace, options);
  summary.photometric_seconds = photometric_seconds;
  summary.geometric_seconds = SecondsSince(start);
  summary.resumed_estimates = resumed.estimates;
  summary.resumed_filtered = resumed.filtered;
  return summary;
}

int RunMultiViewStereoBlock(const Workspace& workspace, const MvsOptions& options, const MvsBlock& block,
                            Progress& progress) {
  options.Check();
  const SparseModel model = ReadSparseModelWithoutKeypoints(workspace.Sparse());
  const DepthPlan plan = PlanWorkspaceDepth(workspace, model, options);
  const bool photometric = block.pass == MvsPass::kPhotometric;
  const std::vector<ViewPlan>& views = photometric ? plan.estimated : plan.written;
  const size_t size = block.size > 0 ? static_cast<size_t>(block.size) : views.size();
  const size_t first = std::min(views.size(), static_cast<size_t>(block.index) * size);
  const std::vector<ViewPlan> in_block(views.begin() + static_cast<std::ptrdiff_t>(first),
                                       views.begin() + static_cast<std::ptrdiff_t>(std::min(views.size(), first + size)));
  fs::create_directories(workspace.StereoEstimates());
  if (photometric) {
    EstimatePhotometric(workspace, model, in_block, options, progress);
  } else {
    FilterAndWriteBlock(workspace, model, plan, in_block, options, progress);
  }
  return static_cast<int>(in_block.size());
}

MvsSummary FinishMultiViewStereoBlocks(const Workspace& workspace, const MvsOptions& options) {
  const SparseModel model = ReadSparseModelWithoutKeypoints(workspace.Sparse());
  const DepthPlan plan = PlanWorkspaceDepth(workspace, model, options);
  MvsSummary summary;
  summary.estimated_views = static_cast<int>(plan.estimated.size());
  summary.skipped = SkippedViews(model, plan);
  for (const ViewPlan& view : plan.written) {
    const fs::path report = workspace.StereoViewReport(view.name);
    if (!fs::exists(report)) {
      throw BadInputError("the depth of " + view.name + " is not done (no " + report.string() +
                          "): a geometric block did not run or failed");
    }
    summary.views.push_back(nlohmann::json::parse(ReadFileBytes(report)).get<MvsViewReport>());
  }
  fs::remove_all(workspace.StereoEstimates());
  return summary;
}

MvsSummary RunSgbmStereo(const Workspace& workspace, const ViewSelectionOptions& views, const SgbmOptions& options,
                         Progress& progress) {
  options.Check();
  views.Check();
  const SparseModel model = ReadSparseModel(workspace.Sparse());
  const std::vector<ViewPlan> plans = PlanViews(model, views);
  const auto read_photo = [&workspace](const SparseImage& image) { return ReadImage(workspace.Image(image.name)); };
  MvsSummary summary;
  summary.estimated_views = static_cast<int>(plans.size());
  const auto start = std::chrono::steady_clock::now();
  const auto total = static_cast<int64_t>(plans.size());
  for (size_t i = 0; i < plans.size(); ++i) {
    progress.Update("sgbm", static_cast<int64_t>(i), total);
    std::optional<SgbmViewDepth> view = SgbmStereoView(model, plans[i], read_photo, options);
    if (!view) {
      summary.skipped.push_back(plans[i].name + ": no source view to its right for rectified stereo");
      continue;
    }
    WriteDepthExr(workspace.Depth(plans[i].name), view->depth);
    WriteDepthExr(workspace.DepthConfidence(plans[i].name), view->confidence);
    summary.views.push_back(std::move(view->report));
  }
  progress.Update("sgbm", total, total);
  summary.photometric_seconds = SecondsSince(start);
  return summary;
}

}  // namespace parallax

#include "mvs/mvs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <map>
#include <set>

#include <opencv2/imgproc.hpp>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/error.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "core/check.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

GrayImage LoadGray(const fs::path& path) {
  const Image image = ReadImage(path);
  GrayImage gray{image.Width(), image.Height(), {}};
  gray.values.resize(static_cast<size_t>(image.Width()) * image.Height());
  const int channels = image.Channels();
  for (size_t i = 0; i < gray.values.size(); ++i) {
    const float* pixel = image.Pixels().data() + i * channels;
    gray.values[i] = channels >= 3 ? 0.299f * pixel[0] + 0.587f * pixel[1] + 0.114f * pixel[2]
                                   : pixel[0];
  }
  return gray;
}

// The camera `image` is estimated with at the working resolution `options` choose for it.
Camera WorkingCameraOf(const SparseModel& model, const SparseImage& image, const MvsOptions& options) {
  const Camera& camera = model.CameraById(image.camera_id);
  return WorkingCamera(camera, options.ScaleFor(static_cast<int>(camera.width), static_cast<int>(camera.height)));
}

// The photo resampled to its working camera's size (area averaging, no aliasing).
GrayImage ResampleTo(const GrayImage& image, const Camera& camera) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  if (image.width == width && image.height == height) return image;
  const cv::Mat full(image.height, image.width, CV_32F, const_cast<float*>(image.values.data()));
  cv::Mat small;
  cv::resize(full, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return {width, height, std::vector<float>(small.begin<float>(), small.end<float>())};
}

DepthMap UpsampleNearest(const DepthMap& depth, const std::vector<size_t>& nearest, int width, int height) {
  DepthMap full(width, height);
  for (size_t i = 0; i < nearest.size(); ++i) full.Values()[i] = depth.Values()[nearest[i]];
  return full;
}

DepthNormalMap UpsampleNearest(const DepthNormalMap& estimate, const std::vector<size_t>& nearest, int width,
                               int height) {
  DepthNormalMap full{UpsampleNearest(estimate.depth, nearest, width, height),
                      std::vector<float>(3 * nearest.size()), std::vector<float>(estimate.cost.empty() ? 0 : nearest.size())};
  for (size_t i = 0; i < nearest.size(); ++i) {
    if (!estimate.cost.empty()) full.cost[i] = estimate.cost[nearest[i]];
    for (size_t c = 0; c < 3; ++c) full.normal[3 * i + c] = estimate.normal[3 * nearest[i] + c];
  }
  return full;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double ValidShare(const DepthMap& depth) {
  size_t valid = 0;
  for (const float value : depth.Values()) valid += value > 0;
  return static_cast<double>(valid) / static_cast<double>(std::max<size_t>(1, depth.Values().size()));
}

DenseArray NormalArray(const DepthNormalMap& map, const DepthMap& keep) {
  const int width = keep.Width(), height = keep.Height();
  DenseArray array{width, height, 3, std::vector<float>(static_cast<size_t>(width) * height * 3)};
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < static_cast<size_t>(width) * height; ++i) {
      array.values[c * static_cast<size_t>(width) * height + i] =
          keep.Values()[i] > 0 ? map.normal[3 * i + c] : 0.0f;
    }
  }
  return array;
}

}  // namespace

void MvsOptions::Check() const {
  views.Check();
  patch_match.Check();
  filter.Check();
  RequireOption(filter_sources >= 1, "MvsOptions.filter_sources", filter_sources, ">= 1");
  RequireOption(image_scale >= 0.25 && image_scale <= 1, "MvsOptions.image_scale", image_scale, "[0.25, 1]");
  RequireOption(max_image_size == 0 || max_image_size >= 64, "MvsOptions.max_image_size", max_image_size,
                "0 (no cap) or >= 64");
}

double MvsOptions::ScaleFor(int width, int height) const {
  return WorkingScale(width, height, image_scale, max_image_size);
}

int MaxImageSizeFor(Quality quality) {
  switch (quality) {
    case Quality::kFast: return 768;
    case Quality::kBalanced: return 1024;
    case Quality::kBest: return 1600;
  }
  return 0;
}

MvsOptions MvsOptionsFor(Quality quality) {
  MvsOptions options;
  options.max_image_size = MaxImageSizeFor(quality);
  switch (quality) {
    case Quality::kFast:
      options.views.max_sources = 3;
      options.patch_match.iterations = 2;
      options.patch_match.far_neighbour_offset = 0;
      break;
    case Quality::kBalanced:
      break;
    case Quality::kBest:
      // Measured: a larger window (5x5 samples) or requiring two agreeing views lowered
      // completeness more than the error; more sources and sweeps raise both accuracy and time.
      options.views.max_sources = 7;
      options.patch_match.iterations = 4;
      break;
  }
  return options;
}

DepthMap ToColmapSampling(const DepthMap& depth) {
  DepthMap sampled(depth.Width(), depth.Height());
  for (int y = 0; y < depth.Height(); ++y) {
    for (int x = 0; x < depth.Width(); ++x) {
      sampled.At(x, y) = static_cast<float>(SampleDepth(depth, Eigen::Vector2d(x, y), 1.01).value_or(0));
    }
  }
  return sampled;
}

namespace {

// The views whose depth is written (`written`) and those PatchMatch runs on (`estimated`): the
// written ones plus the sources the geometric filter checks them against.
struct DepthPlan {
  std::set<std::string> wanted;  // MvsOptions::only_views; empty: every view.
  std::vector<ViewPlan> all;
  std::vector<ViewPlan> written;
  std::vector<ViewPlan> estimated;
};

DepthPlan PlanDepth(const SparseModel& model, const MvsOptions& options, const fs::path& workspace) {
  DepthPlan plan;
  plan.all = PlanViews(model, options.views);
  plan.wanted = {options.only_views.begin(), options.only_views.end()};
  const std::set<std::string>& wanted = plan.wanted;
  std::set<uint32_t> estimated;
  for (const ViewPlan& view : plan.all) {
    if (!wanted.empty() && !wanted.count(view.name)) continue;
    plan.written.push_back(view);
    estimated.insert(view.image_id);
    const size_t filter_sources = wanted.empty() ? view.sources.size()
                                                 : std::min(view.sources.size(), static_cast<size_t>(options.filter_sources));
    estimated.insert(view.sources.begin(), view.sources.begin() + static_cast<std::ptrdiff_t>(filter_sources));
  }
  for (const ViewPlan& view : plan.all) {
    if (estimated.count(view.image_id)) plan.estimated.push_back(view);
  }
  for (const std::string& name : wanted) {
    if (!model.FindImageByName(name)) {
      throw BadInputError(workspace.string() + ": no image named " + name + " in the sparse model");
    }
  }
  return plan;
}

// Why each image of the model gets no depth map.
std::vector<std::string> SkippedViews(const SparseModel& model, const DepthPlan& plan) {
  const std::set<std::string>& wanted = plan.wanted;
  std::vector<std::string> skipped;
  for (const SparseImage& image : model.Images()) {
    const bool planned = std::any_of(plan.all.begin(), plan.all.end(),
                                     [&](const ViewPlan& view) { return view.image_id == image.id; });
    if (!planned) {
      skipped.push_back(image.name + ": too few sparse points or no source view");
    } else if (!wanted.empty() && !wanted.count(image.name)) {
      skipped.push_back(image.name + ": not requested");
    }
  }
  return skipped;
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
    view.camera = WorkingCameraOf(model, image, options);
    view.cam_from_world = image.cam_from_world;
    view.image = ResampleTo(LoadGray(ws.Image(image.name)), view.camera);
  }
  previous.clear();
  return views;
}

// A photometric estimate between the passes: depth, normal (3) and cost planes.
void WriteEstimate(const std::filesystem::path& path, const DepthNormalMap& estimate) {
  const size_t pixels = estimate.depth.Values().size();
  DenseArray array{estimate.depth.Width(), estimate.depth.Height(), 5, std::vector<float>(5 * pixels)};
  for (size_t i = 0; i < pixels; ++i) {
    array.values[i] = estimate.depth.Values()[i];
    for (size_t c = 0; c < 3; ++c) array.values[(1 + c) * pixels + i] = estimate.normal[3 * i + c];
    array.values[4 * pixels + i] = estimate.cost[i];
  }
  WriteColmapArray(path, array);
}

DepthNormalMap ReadEstimate(const std::filesystem::path& path) {
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
    std::vector<const StereoView*> sources;
    for (uint32_t id : plan.sources) sources.push_back(&views.at(id));
    PatchMatchOptions patch_match = options.patch_match;
    patch_match.min_depth = plan.min_depth;
    patch_match.max_depth = plan.max_depth;
    patch_match.seed = plan.image_id;
    WriteEstimate(ws.StereoEstimate(plan.name), PatchMatchStereo(views.at(plan.image_id), sources, patch_match));
  }
  progress.Update("depth", total, total);
}

// The view's maps in both formats, at the photo's size whatever the resolution of the estimate;
// sets the shares of pixels with depth in what was written.
void WriteViewDepth(const Workspace& ws, const Camera& camera, const DepthNormalMap& low,
                    FilteredDepth filtered, MvsViewReport& report) {
  const std::string& name = report.name;
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  const bool same_size = low.depth.Width() == width && low.depth.Height() == height;
  const std::vector<size_t> nearest =
      same_size ? std::vector<size_t>() : PixelsAtCentres(low.depth.Width(), low.depth.Height(), width, height);
  const DepthNormalMap estimate = same_size ? low : UpsampleNearest(low, nearest, width, height);
  if (!same_size) {
    filtered.depth = UpsampleNearest(filtered.depth, nearest, width, height);
    filtered.confidence = UpsampleNearest(filtered.confidence, nearest, width, height);
  }
  WriteColmapDepth(ws.StereoDepthMap(name, StereoPass::kPhotometric), ToColmapSampling(estimate.depth));
  WriteColmapDepth(ws.StereoDepthMap(name, StereoPass::kGeometric), ToColmapSampling(filtered.depth));
  WriteColmapArray(ws.StereoNormalMap(name, StereoPass::kPhotometric), NormalArray(estimate, estimate.depth));
  WriteColmapArray(ws.StereoNormalMap(name, StereoPass::kGeometric), NormalArray(estimate, filtered.depth));
  WriteDepthExr(ws.Depth(name), filtered.depth);
  WriteDepthExr(ws.DepthConfidence(name), filtered.confidence);
  report.photometric_share = ValidShare(estimate.depth);
  report.geometric_share = ValidShare(filtered.depth);
}

// The geometric pass for one view: its estimate checked against its sources' (read back from
// <ws>/stereo/estimates), written in both formats. Needs no images, only cameras and poses.
MvsViewReport FilterAndWriteView(const Workspace& ws, const SparseModel& model, const ViewPlan& view,
                                 const std::set<std::string>& estimated, const MvsOptions& options) {
  const auto working_view = [&](uint32_t id) {
    const SparseImage& image = model.ImageById(id);
    StereoView stereo_view;
    stereo_view.camera = WorkingCameraOf(model, image, options);
    stereo_view.cam_from_world = image.cam_from_world;
    return stereo_view;
  };
  std::vector<StereoView> source_views;
  std::vector<DepthNormalMap> source_estimates;
  for (const uint32_t id : view.sources) {
    const std::string& name = model.ImageById(id).name;
    if (!estimated.count(name)) continue;
    source_views.push_back(working_view(id));
    source_estimates.push_back(ReadEstimate(ws.StereoEstimate(name)));
  }
  std::vector<std::pair<const StereoView*, const DepthNormalMap*>> sources;
  for (size_t s = 0; s < source_views.size(); ++s) sources.emplace_back(&source_views[s], &source_estimates[s]);
  const DepthNormalMap low = ReadEstimate(ws.StereoEstimate(view.name));
  FilteredDepth filtered =
      sources.empty() ? FilteredDepth{DepthMap(low.depth.Width(), low.depth.Height()),
                                      DepthMap(low.depth.Width(), low.depth.Height())}
                      : FilterGeometric(working_view(view.image_id), low, sources, options.filter);
  MvsViewReport report;
  report.name = view.name;
  for (uint32_t id : view.sources) report.sources.push_back(model.ImageById(id).name);
  report.min_depth = view.min_depth;
  report.max_depth = view.max_depth;
  report.working_width = low.depth.Width();
  report.working_height = low.depth.Height();
  const Camera& camera = model.CameraById(model.ImageById(view.image_id).camera_id);
  WriteViewDepth(ws, camera, low, std::move(filtered), report);
  return report;
}

}  // namespace

MvsSummary RunMultiViewStereo(const fs::path& workspace, const MvsOptions& options,
                              Progress& progress) {
  const Workspace ws(workspace);
  fs::remove_all(ws.StereoEstimates());
  auto start = std::chrono::steady_clock::now();
  RunMultiViewStereoBlock(workspace, options, {MvsPass::kPhotometric}, progress);
  const double photometric_seconds = Seconds(start);
  start = std::chrono::steady_clock::now();
  RunMultiViewStereoBlock(workspace, options, {MvsPass::kGeometric}, progress);
  MvsSummary summary = FinishMultiViewStereoBlocks(workspace, options);
  summary.photometric_seconds = photometric_seconds;
  summary.geometric_seconds = Seconds(start);
  return summary;
}

int RunMultiViewStereoBlock(const fs::path& workspace, const MvsOptions& options, const MvsBlock& block,
                            Progress& progress) {
  options.Check();
  const Workspace ws(workspace);
  const SparseModel model = ReadSparseModelWithoutKeypoints(ws.Sparse());
  const DepthPlan plan = PlanDepth(model, options, workspace);
  const bool photometric = block.pass == MvsPass::kPhotometric;
  const std::vector<ViewPlan>& views = photometric ? plan.estimated : plan.written;
  const size_t size = block.size > 0 ? static_cast<size_t>(block.size) : views.size();
  const size_t first = std::min(views.size(), static_cast<size_t>(block.index) * size);
  const std::vector<ViewPlan> in_block(views.begin() + static_cast<std::ptrdiff_t>(first),
                                       views.begin() + static_cast<std::ptrdiff_t>(std::min(views.size(), first + size)));
  fs::create_directories(ws.StereoEstimates());
  if (photometric) {
    EstimatePhotometric(ws, model, in_block, options, progress);
    return static_cast<int>(in_block.size());
  }
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
  return static_cast<int>(in_block.size());
}

MvsSummary FinishMultiViewStereoBlocks(const fs::path& workspace, const MvsOptions& options) {
  const Workspace ws(workspace);
  const SparseModel model = ReadSparseModelWithoutKeypoints(ws.Sparse());
  const DepthPlan plan = PlanDepth(model, options, workspace);
  MvsSummary summary;
  summary.estimated_views = static_cast<int>(plan.estimated.size());
  summary.skipped = SkippedViews(model, plan);
  for (const ViewPlan& view : plan.written) {
    const fs::path report = ws.StereoViewReport(view.name);
    if (!fs::exists(report)) {
      throw BadInputError("the depth of " + view.name + " is not done (no " + report.string() +
                          "): a geometric block did not run or failed");
    }
    summary.views.push_back(nlohmann::json::parse(ReadFileBytes(report)).get<MvsViewReport>());
  }
  fs::remove_all(ws.StereoEstimates());
  return summary;
}

}  // namespace parallax

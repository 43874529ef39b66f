#include "mvs/mvs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <map>
#include <set>

#include <opencv2/imgproc.hpp>

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

// The photo at `scale` of its size (area averaging, no aliasing), with its camera to match:
// pixel coordinates (origin at the image corner) scale by the exact size ratio per axis.
void ScaleView(StereoView& view, double scale) {
  if (scale == 1) return;
  const int width = std::max(1, static_cast<int>(std::lround(view.image.width * scale)));
  const int height = std::max(1, static_cast<int>(std::lround(view.image.height * scale)));
  const cv::Mat full(view.image.height, view.image.width, CV_32F, view.image.values.data());
  cv::Mat small;
  cv::resize(full, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  view.image = {width, height, std::vector<float>(small.begin<float>(), small.end<float>())};
  const double sx = static_cast<double>(width) / static_cast<double>(view.camera.width);
  const double sy = static_cast<double>(height) / static_cast<double>(view.camera.height);
  view.camera = MakePinholeCamera(view.camera.id, static_cast<uint64_t>(width), static_cast<uint64_t>(height),
                                  view.camera.FocalX() * sx, view.camera.FocalY() * sy,
                                  view.camera.PrincipalX() * sx, view.camera.PrincipalY() * sy);
}

// Back to the photo's size, nearest: for each pixel of a width x height image (row-major), the
// index of the low_width x low_height pixel its centre falls in.
std::vector<size_t> NearestLowResolutionPixels(int low_width, int low_height, int width, int height) {
  std::vector<size_t> nearest;
  nearest.reserve(static_cast<size_t>(width) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    const int ly = std::min(low_height - 1, static_cast<int>((y + 0.5) * low_height / height));
    for (int x = 0; x < width; ++x) {
      const int lx = std::min(low_width - 1, static_cast<int>((x + 0.5) * low_width / width));
      nearest.push_back(static_cast<size_t>(ly) * static_cast<size_t>(low_width) + static_cast<size_t>(lx));
    }
  }
  return nearest;
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
}

MvsOptions MvsOptionsFor(Quality quality) {
  MvsOptions options;
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

// Every image that takes part, as reference or as source, loaded once at the estimate's scale.
std::map<uint32_t, StereoView> LoadStereoViews(const Workspace& ws, const SparseModel& model,
                                               const std::vector<ViewPlan>& plans, double scale) {
  std::map<uint32_t, StereoView> views;
  for (const ViewPlan& plan : plans) {
    for (uint32_t id : plan.sources) views[id];
    views[plan.image_id];
  }
  for (auto& [id, view] : views) {
    const SparseImage& image = model.ImageById(id);
    view.camera = model.CameraById(image.camera_id);
    view.cam_from_world = image.cam_from_world;
    view.image = LoadGray(ws.Image(image.name));
    ScaleView(view, scale);
  }
  return views;
}

std::map<uint32_t, DepthNormalMap> EstimatePhotometric(const std::map<uint32_t, StereoView>& views,
                                                       const std::vector<ViewPlan>& plans,
                                                       const PatchMatchOptions& options, Progress& progress) {
  std::map<uint32_t, DepthNormalMap> estimates;
  const auto total = static_cast<int64_t>(plans.size());
  for (size_t i = 0; i < plans.size(); ++i) {
    progress.Update("depth", static_cast<int64_t>(i), total);
    const ViewPlan& plan = plans[i];
    std::vector<const StereoView*> sources;
    for (uint32_t id : plan.sources) sources.push_back(&views.at(id));
    PatchMatchOptions patch_match = options;
    patch_match.min_depth = plan.min_depth;
    patch_match.max_depth = plan.max_depth;
    patch_match.seed = plan.image_id;
    estimates[plan.image_id] = PatchMatchStereo(views.at(plan.image_id), sources, patch_match);
  }
  progress.Update("depth", total, total);
  return estimates;
}

// The view's maps in both formats, at the photo's size whatever the resolution of the estimate;
// sets the shares of pixels with depth in what was written.
void WriteViewDepth(const Workspace& ws, const Camera& camera, const DepthNormalMap& low,
                    FilteredDepth filtered, MvsViewReport& report) {
  const std::string& name = report.name;
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  const bool same_size = low.depth.Width() == width && low.depth.Height() == height;
  const std::vector<size_t> nearest =
      same_size ? std::vector<size_t>() : NearestLowResolutionPixels(low.depth.Width(), low.depth.Height(), width, height);
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

}  // namespace

MvsSummary RunMultiViewStereo(const fs::path& workspace, const MvsOptions& options,
                              Progress& progress) {
  options.Check();
  const Workspace ws(workspace);
  const SparseModel model = ReadSparseModel(ws.Sparse());
  const DepthPlan plan = PlanDepth(model, options, workspace);
  MvsSummary summary;
  summary.estimated_views = static_cast<int>(plan.estimated.size());
  summary.skipped = SkippedViews(model, plan);
  const std::map<uint32_t, StereoView> views = LoadStereoViews(ws, model, plan.estimated, options.image_scale);

  auto start = std::chrono::steady_clock::now();
  const std::map<uint32_t, DepthNormalMap> estimates =
      EstimatePhotometric(views, plan.estimated, options.patch_match, progress);
  summary.photometric_seconds = Seconds(start);

  start = std::chrono::steady_clock::now();
  const auto total = static_cast<int64_t>(plan.written.size());
  for (size_t i = 0; i < plan.written.size(); ++i) {
    progress.Update("filter", static_cast<int64_t>(i), total);
    const ViewPlan& view = plan.written[i];
    std::vector<std::pair<const StereoView*, const DepthNormalMap*>> sources;
    for (uint32_t id : view.sources) {
      if (estimates.count(id)) sources.emplace_back(&views.at(id), &estimates.at(id));
    }
    const DepthNormalMap& low = estimates.at(view.image_id);
    FilteredDepth filtered =
        sources.empty() ? FilteredDepth{DepthMap(low.depth.Width(), low.depth.Height()),
                                        DepthMap(low.depth.Width(), low.depth.Height())}
                        : FilterGeometric(views.at(view.image_id), low, sources, options.filter);
    const Camera& camera = model.CameraById(model.ImageById(view.image_id).camera_id);
    MvsViewReport report;
    report.name = view.name;
    for (uint32_t id : view.sources) report.sources.push_back(model.ImageById(id).name);
    report.min_depth = view.min_depth;
    report.max_depth = view.max_depth;
    WriteViewDepth(ws, camera, low, std::move(filtered), report);
    summary.views.push_back(std::move(report));
  }
  progress.Update("filter", total, total);
  summary.geometric_seconds = Seconds(start);
  return summary;
}

}  // namespace parallax

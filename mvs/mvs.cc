#include "mvs/mvs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/check.h"

namespace parallax {
namespace {

// The photo in grey at its own size.
GrayImage ToGray(const Image& image) {
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

// The photo resampled to its working camera's size (area averaging, no aliasing).
GrayImage ResampleTo(const GrayImage& image, const Camera& camera) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  if (image.width == width && image.height == height) return image;
  const cv::Mat full(image.height, image.width, CV_32F, const_cast<float*>(image.values.data()));
  cv::Mat small;
  cv::resize(full, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return {width, height, std::vector<float>(small.begin<float>(), small.end<float>())};
}

double ValidShare(const DepthMap& depth) {
  size_t valid = 0;
  for (const float value : depth.Values()) valid += value > 0;
  return static_cast<double>(valid) / static_cast<double>(std::max<size_t>(1, depth.Values().size()));
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
      options.patch_match.propagation_reach = 1;
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
  tbb::parallel_for(0, depth.Height(), [&](int y) {
    for (int x = 0; x < depth.Width(); ++x) {
      sampled.At(x, y) = static_cast<float>(SampleDepth(depth, Eigen::Vector2d(x, y), 1.01).value_or(0));
    }
  });
  return sampled;
}

DenseArray ColmapNormalMap(const DepthNormalMap& map, const DepthMap& keep) {
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

DepthPlan PlanDepth(const SparseModel& model, const MvsOptions& options) {
  options.Check();
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
    if (!model.FindImageByName(name)) throw BadInputError("no image named " + name + " in the sparse model");
  }
  return plan;
}

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

StereoView WorkingStereoView(const SparseModel& model, const SparseImage& image, const MvsOptions& options) {
  const Camera& camera = model.CameraById(image.camera_id);
  StereoView view;
  view.camera = WorkingCamera(camera, options.ScaleFor(static_cast<int>(camera.width), static_cast<int>(camera.height)));
  view.cam_from_world = image.cam_from_world;
  return view;
}

GrayImage WorkingGray(const Image& photo, const Camera& camera) { return ResampleTo(ToGray(photo), camera); }

DepthNormalMap EstimateViewDepth(const ViewPlan& plan, const std::map<uint32_t, StereoView>& views,
                                 const MvsOptions& options) {
  std::vector<const StereoView*> sources;
  for (uint32_t id : plan.sources) sources.push_back(&views.at(id));
  PatchMatchOptions patch_match = options.patch_match;
  patch_match.min_depth = plan.min_depth;
  patch_match.max_depth = plan.max_depth;
  patch_match.seed = plan.image_id + options.seed;
  return PatchMatchStereo(views.at(plan.image_id), sources, patch_match);
}

ViewDepth FilterViewDepth(const SparseModel& model, const ViewPlan& view, const DepthNormalMap& low,
                          const std::map<uint32_t, DepthNormalMap>& source_estimates, const MvsOptions& options) {
  const auto working_view = [&](uint32_t id) { return WorkingStereoView(model, model.ImageById(id), options); };
  std::vector<StereoView> source_views;
  std::vector<const DepthNormalMap*> estimates;
  for (const uint32_t id : view.sources) {
    const auto found = source_estimates.find(id);
    if (found == source_estimates.end()) continue;
    source_views.push_back(working_view(id));
    estimates.push_back(&found->second);
  }
  std::vector<std::pair<const StereoView*, const DepthNormalMap*>> sources;
  for (size_t s = 0; s < source_views.size(); ++s) sources.emplace_back(&source_views[s], estimates[s]);
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
  report.photometric_share = ValidShare(low.depth);
  report.geometric_share = ValidShare(filtered.depth);
  return {low, std::move(filtered), std::move(report)};
}

}  // namespace parallax

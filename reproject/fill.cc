#include "reproject/fill.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>
#include <tbb/parallel_for.h>

#include "core/check.h"
#include "core/error.h"
#include "reproject/depth_aware_fill.h"

namespace parallax {
namespace {

// The mean of the surface fills around (x, y) at one level of a pyramid of (color sum, count)
// (SmoothSurfaceFill), bilinear between its cells.
cv::Vec3f PyramidMean(const cv::Mat& level, int width, int height, int x, int y) {
  const float u = std::max(0.0f, (static_cast<float>(x) + 0.5f) * static_cast<float>(level.cols) / static_cast<float>(width) - 0.5f);
  const float v = std::max(0.0f, (static_cast<float>(y) + 0.5f) * static_cast<float>(level.rows) / static_cast<float>(height) - 0.5f);
  const int u0 = std::min(static_cast<int>(u), level.cols - 1), v0 = std::min(static_cast<int>(v), level.rows - 1);
  const int u1 = std::min(u0 + 1, level.cols - 1), v1 = std::min(v0 + 1, level.rows - 1);
  const float fu = u - static_cast<float>(u0), fv = v - static_cast<float>(v0);
  const cv::Vec4f sum = (1 - fv) * ((1 - fu) * level.at<cv::Vec4f>(v0, u0) + fu * level.at<cv::Vec4f>(v0, u1)) +
                        fv * ((1 - fu) * level.at<cv::Vec4f>(v1, u0) + fu * level.at<cv::Vec4f>(v1, u1));
  return {sum[0] / sum[3], sum[1] / sum[3], sum[2] / sum[3]};
}

// The depth-aware fill's surface colors change with the direction in which each march meets
// the rim, so far from the rim they fan out in streaks. Each surface fill becomes the mean of
// the surface fills around it, over a window about half as wide as its distance to the nearest
// pixel that is not one (a pyramid of area means, levels interpolated): beside the rim the
// rim's detail stays, far from it the fill is the rim's mean color. Sky fills, samples and
// pixels left empty are not touched and do not count.
void SmoothSurfaceFill(const ClassMap& classes, const FillOptions& options, BlendResult* blend) {
  const int width = classes.width, height = classes.height;
  cv::Mat mask(height, width, CV_8UC1);
  cv::Mat pyramid_base(height, width, CV_32FC4);
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const bool surface = ShouldFill(classes.At(x, y), options) && blend->Kind(x, y) == SampleKind::kNone &&
                           blend->depth.At(x, y) > 0;
      mask.at<uint8_t>(y, x) = surface ? 1 : 0;
      const float w = surface ? 1.0f : 0.0f;
      pyramid_base.at<cv::Vec4f>(y, x) = {w * blend->color.At(x, y, 0), w * blend->color.At(x, y, 1),
                                          w * blend->color.At(x, y, 2), w};
    }
  });
  if (cv::countNonZero(mask) == 0) return;
  cv::Mat distance;
  cv::distanceTransform(mask, distance, cv::DIST_L2, cv::DIST_MASK_5);
  constexpr int kLevels = 7;  // Cells of 1, 2, ..., 64 pixels.
  std::array<cv::Mat, kLevels> pyramid;
  pyramid[0] = pyramid_base;
  for (size_t k = 1; k < pyramid.size(); ++k) {
    const cv::Mat& finer = pyramid[k - 1];
    cv::resize(finer, pyramid[k], cv::Size((finer.cols + 1) / 2, (finer.rows + 1) / 2), 0, 0, cv::INTER_AREA);
  }
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) continue;
      const float cell = 0.5f * distance.at<float>(y, x);
      if (cell <= 1) continue;
      const float level = std::min(std::log2(cell), static_cast<float>(kLevels - 1));
      const int low = static_cast<int>(level);
      const int high = std::min(low + 1, kLevels - 1);
      const float t = level - static_cast<float>(low);
      const cv::Vec3f mean = (1 - t) * PyramidMean(pyramid[static_cast<size_t>(low)], width, height, x, y) +
                             t * PyramidMean(pyramid[static_cast<size_t>(high)], width, height, x, y);
      if (!std::isfinite(mean[0] + mean[1] + mean[2])) continue;  // No weight: keep the fill's color.
      for (int ch = 0; ch < 3; ++ch) blend->color.At(x, y, ch) = mean[ch];
    }
  });
}

uint8_t ToSrgb8(float linear) {
  const float encoded = LinearToSrgb(std::clamp(linear, 0.0f, 1.0f));
  return static_cast<uint8_t>(std::lround(encoded * 255.0f));
}

int FillInpaint(const ClassMap& classes, const FillOptions& options, BlendResult* blend) {
  const int width = classes.width, height = classes.height;
  cv::Mat src(height, width, CV_8UC3), mask(height, width, CV_8UC1);
  int to_fill = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool fill = ShouldFill(classes.At(x, y), options);
      to_fill += fill ? 1 : 0;
      mask.at<uint8_t>(y, x) = fill ? 255 : 0;
      cv::Vec3b& pixel = src.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) pixel[c] = ToSrgb8(blend->color.At(x, y, c));
    }
  }
  // Telea needs at least one known pixel to propagate from.
  if (to_fill == 0 || to_fill == width * height) return 0;
  cv::Mat dst;
  cv::inpaint(src, mask, dst, options.inpaint_radius_px, cv::INPAINT_TELEA);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec3b& pixel = dst.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) blend->color.At(x, y, c) = SrgbToLinear(pixel[c] / 255.0f);
    }
  }
  return to_fill;
}

}  // namespace

void FillOptions::Check() const {
  RequireOption(directions == 8 || directions == 16, "FillOptions.directions", directions, "8 or 16");
  RequireOption(background_tolerance > 0 && background_tolerance < 1, "FillOptions.background_tolerance",
                background_tolerance, "(0, 1)");
  RequireOption(hole_sky_share > 0 && hole_sky_share <= 1, "FillOptions.hole_sky_share", hole_sky_share, "(0, 1]");
  RequireOption(inpaint_radius_px > 0 && std::isfinite(inpaint_radius_px), "FillOptions.inpaint_radius_px",
                inpaint_radius_px, "> 0");
}

FillSummary FillHoles(const ClassMap& classes, const Camera& camera, const FillOptions& options,
                      BlendResult* blend) {
  options.Check();
  const Pinhole pinhole = Pinhole::From(camera);
  if (classes.width != blend->color.Width() || classes.height != blend->color.Height()) {
    throw InternalError("FillHoles: class map " + std::to_string(classes.width) + "x" +
                        std::to_string(classes.height) + " does not match the image " +
                        std::to_string(blend->color.Width()) + "x" +
                        std::to_string(blend->color.Height()));
  }
  if (!classes.open_to_sky.empty() && classes.open_to_sky.size() != classes.classes.size()) {
    throw InternalError("FillHoles: open_to_sky has " +
                        std::to_string(classes.open_to_sky.size()) + " entries for " +
                        std::to_string(classes.classes.size()) + " pixels");
  }
  if (pinhole.width != classes.width || pinhole.height != classes.height) {
    throw InternalError("FillHoles: camera " + std::to_string(pinhole.width) + "x" +
                        std::to_string(pinhole.height) + " does not match the image " +
                        std::to_string(classes.width) + "x" +
                        std::to_string(classes.height));
  }
  FillSummary summary;
  const ClassCounts counts = CountClasses(classes);
  const size_t fillable = counts[PixelClass::kCrack] + counts[PixelClass::kDisocclusion] +
                          (options.fill_out_of_view ? counts[PixelClass::kOutOfView] : 0);
  if (fillable == 0) {
    summary.skipped = "no holes to fill";
  } else if (options.method == FillMethod::kNone) {
    summary.skipped = "not requested (fill none)";
  } else if (options.method == FillMethod::kDepthAware) {
    summary.filled_px = FillDepthAware(classes, pinhole, options, blend);
    if (options.smooth) SmoothSurfaceFill(classes, options, blend);
  } else if (options.method == FillMethod::kInpaint) {
    summary.filled_px = FillInpaint(classes, options, blend);
  }
  const size_t total = classes.classes.size();
  const size_t empty = total - counts[PixelClass::kCovered] - counts[PixelClass::kBackground];
  const size_t left = empty - std::min(empty, static_cast<size_t>(summary.filled_px));
  summary.hole_ratio_filled = total == 0 ? 0.0 : static_cast<double>(left) / static_cast<double>(total);
  return summary;
}

}  // namespace parallax

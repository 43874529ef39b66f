#include "eval/misalignment.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/error.h"

namespace parallax {
namespace {

// Rec. 709 luma of an sRGB image, 8-bit (what DIS flow takes).
cv::Mat Luma8(const Image& image) {
  cv::Mat luma(image.Height(), image.Width(), CV_8UC1);
  for (int y = 0; y < image.Height(); ++y) {
    const float* row = image.Row(y);
    auto* out = luma.ptr<uint8_t>(y);
    for (int x = 0; x < image.Width(); ++x) {
      const float* pixel = row + static_cast<size_t>(x) * image.Channels();
      const float value = 0.2126f * pixel[0] + 0.7152f * pixel[1] + 0.0722f * pixel[2];
      out[x] = static_cast<uint8_t>(std::lround(255 * std::clamp(value, 0.0f, 1.0f)));
    }
  }
  return luma;
}

// The value below which `share` of `values` lie (the nearest rank); reorders them.
double Quantile(std::vector<float>& values, double share) {
  const auto rank = static_cast<size_t>(share * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank), values.end());
  return values[rank];
}

}  // namespace

Image FlowLength(const Image& render, const Image& photo) {
  if (render.Width() != photo.Width() || render.Height() != photo.Height() || render.Channels() < 3 ||
      photo.Channels() < 3) {
    throw InternalError("flow length: need two RGB images of the same size");
  }
  // The medium preset: its finest scale is the full image, where a sub-pixel offset shows.
  const cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  cv::Mat flow;
  dis->calc(Luma8(render), Luma8(photo), flow);
  Image length(render.Width(), render.Height(), 1);
  for (int y = 0; y < render.Height(); ++y) {
    const auto* vectors = flow.ptr<cv::Vec2f>(y);
    float* out = length.Row(y);
    for (int x = 0; x < render.Width(); ++x) {
      const float value = std::hypot(vectors[x][0], vectors[x][1]);
      out[x] = std::isfinite(value) ? value : 0.0f;
    }
  }
  return length;
}

std::vector<uint8_t> TexturedPixels(const Image& photo) {
  if (photo.Channels() < 3) throw InternalError("textured pixels: need an RGB image");
  constexpr int kWindow = 5, kSobel = 3;
  constexpr float kMinEigenvalue = 1e-4f;
  cv::Mat eigenvalue;
  cv::cornerMinEigenVal(Luma8(photo), eigenvalue, kWindow, kSobel);
  std::vector<uint8_t> textured(static_cast<size_t>(photo.Width()) * photo.Height());
  for (int y = 0; y < photo.Height(); ++y) {
    const float* row = eigenvalue.ptr<float>(y);
    for (int x = 0; x < photo.Width(); ++x) {
      textured[static_cast<size_t>(y) * photo.Width() + x] = row[x] >= kMinEigenvalue;
    }
  }
  return textured;
}

Misalignment MisalignmentOf(const Image& flow_length, const std::vector<uint8_t>& mask) {
  if (mask.size() != flow_length.Pixels().size()) throw InternalError("misalignment: mask and flow sizes differ");
  std::vector<float> lengths;
  for (size_t p = 0; p < mask.size(); ++p) {
    if (mask[p]) lengths.push_back(flow_length.Pixels()[p]);
  }
  if (lengths.empty()) return {};
  Misalignment misalignment;
  misalignment.median_px = Quantile(lengths, 0.5);
  misalignment.p90_px = Quantile(lengths, 0.9);
  return misalignment;
}

}  // namespace parallax

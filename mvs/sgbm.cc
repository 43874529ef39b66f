#include "mvs/sgbm.h"

#include <cmath>
#include <optional>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/check.h"

namespace parallax {
namespace {

// OpenCV's pixel centres lie at integers, COLMAP's at integer + 0.5.
cv::Mat IntrinsicMatrix(const Camera& camera) {
  return (cv::Mat_<double>(3, 3) << camera.FocalX(), 0, camera.PrincipalX() - 0.5, 0,
          camera.FocalY(), camera.PrincipalY() - 0.5, 0, 0, 1);
}

// 8-bit grey version of a photo.
cv::Mat Gray8(const Image& image) {
  cv::Mat gray(image.Height(), image.Width(), CV_8U);
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      float value = 0;
      for (int c = 0; c < std::min(3, image.Channels()); ++c) value += image.At(x, y, c);
      value /= static_cast<float>(std::min(3, image.Channels()));
      gray.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255));
    }
  }
  return gray;
}

constexpr int kRectifiedScale = 2;
// Bounds the matching cost volume (time and memory): nearer points than this allows are lost.
constexpr int kMaxDisparities = 768;

struct RectifiedPair {
  cv::Mat r1, r2, p1, p2, q;  // cv::stereoRectify's outputs.
  cv::Size size;              // Of the rectified images.
};

// The rectification of (reference, source) when the source ends up to the right of the
// reference with a mostly horizontal baseline (what StereoSGBM needs); nullopt otherwise.
std::optional<RectifiedPair> Rectify(const Camera& camera_a, const Rigid3d& a_from_world,
                                     const Camera& camera_b, const Rigid3d& b_from_world) {
  const Rigid3d b_from_a = RelativePose(a_from_world, b_from_world);
  const Eigen::Matrix3d rotation = b_from_a.rotation.toRotationMatrix();
  cv::Mat r(3, 3, CV_64F), t(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.at<double>(i, j) = rotation(i, j);
    t.at<double>(i) = b_from_a.translation(i);
  }
  RectifiedPair pair;
  const cv::Size size(static_cast<int>(camera_a.width), static_cast<int>(camera_a.height));
  // Every photo pixel kept (alpha 1), in a frame large enough not to lose resolution to the
  // rotation that converging cameras need.
  pair.size = cv::Size(size.width * kRectifiedScale, size.height * kRectifiedScale);
  cv::stereoRectify(IntrinsicMatrix(camera_a), cv::noArray(), IntrinsicMatrix(camera_b),
                    cv::noArray(), size, r, t, pair.r1, pair.r2, pair.p1, pair.p2, pair.q,
                    cv::CALIB_ZERO_DISPARITY, 1, pair.size);
  // Horizontal rectification puts -f * baseline in P2(0, 3): negative = source on the right.
  const bool horizontal = std::abs(pair.p2.at<double>(1, 3)) < 1e-9 * std::abs(pair.p2.at<double>(0, 3));
  if (!horizontal || pair.p2.at<double>(0, 3) >= 0) return std::nullopt;
  return pair;
}

// Disparity search window from the view's depth range: d = f * B / z.
void DisparityRange(const RectifiedPair& pair, double min_depth, double max_depth, int& min_disparity,
                    int& num_disparities) {
  const double fb = -pair.p2.at<double>(0, 3);  // f * baseline.
  const int low = static_cast<int>(std::floor(fb / max_depth)) - 2;
  const int high = static_cast<int>(std::ceil(fb / min_depth)) + 2;
  min_disparity = std::max(0, low);
  num_disparities = std::clamp((high - min_disparity + 15) / 16 * 16, 16, kMaxDisparities);
}

// Windows whose grey levels vary less than this (standard deviation, 8-bit levels) are
// textureless: PatchMatch's min_texture_std of 0.004, in 8-bit units.
constexpr double kMinTextureStdLevels = 0.004 * 255;

// Where a disparity of the rectified left image can be trusted: its block_size window lies
// inside the photo and is textured. StereoSGBM itself claims a disparity for flat windows
// (their matching cost is 0 at every disparity, which its uniqueness test does not reject,
// so a constant photo comes back at the minimum disparity everywhere), and windows that
// straddle the photo's edge match the edge of the frame, not the scene.
cv::Mat MatchableMask(const cv::Mat& left, const cv::Mat& map_x, const cv::Mat& map_y,
                      const cv::Size& photo_size, int block_size) {
  const cv::Mat photo(photo_size, CV_8U, cv::Scalar(255));
  cv::Mat inside;
  cv::remap(photo, inside, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  const cv::Size window(block_size, block_size);
  cv::erode(inside, inside, cv::getStructuringElement(cv::MORPH_RECT, window), cv::Point(-1, -1),
            1, cv::BORDER_CONSTANT, 0);
  // Grey levels up to 255 in float: E[I^2] - E[I]^2 keeps ~0.01 levels^2, against a
  // threshold of ~1.
  cv::Mat grey, mean, mean_square;
  left.convertTo(grey, CV_32F);
  cv::boxFilter(grey, mean, CV_32F, window);
  cv::boxFilter(grey.mul(grey), mean_square, CV_32F, window);
  const cv::Mat variance = mean_square - mean.mul(mean);
  const cv::Mat textured = variance >= kMinTextureStdLevels * kMinTextureStdLevels;
  return inside & textured;
}

DepthMap DepthFromDisparity(const cv::Mat& disparity16, const RectifiedPair& pair,
                            const Camera& camera, int min_disparity) {
  cv::Mat disparity;
  disparity16.convertTo(disparity, CV_32F, 1.0 / 16);
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  DepthMap depth(width, height);
  const double f = pair.p1.at<double>(0, 0), cx = pair.p1.at<double>(0, 2), cy = pair.p1.at<double>(1, 2);
  const double fb = -pair.p2.at<double>(0, 3);
  Eigen::Matrix3d to_reference;  // Rectified frame -> reference camera frame: R1^T.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) to_reference(i, j) = pair.r1.at<double>(j, i);
  }
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const double d = static_cast<double>(disparity.at<float>(y, x));
      if (!(d > min_disparity - 1 + 0.5)) continue;  // Invalid disparities are minDisparity - 1.
      const double z = fb / d;
      const Eigen::Vector3d rectified((x - cx) * z / f, (y - cy) * z / f, z);
      const Eigen::Vector3d point = to_reference * rectified;
      if (!(point.z() > 0)) continue;
      // OpenCV pixel (integer centres) -> our pixel index.
      const double u = camera.FocalX() * point.x() / point.z() + camera.PrincipalX() - 0.5;
      const double v = camera.FocalY() * point.y() / point.z() + camera.PrincipalY() - 0.5;
      const int px = static_cast<int>(std::lround(u)), py = static_cast<int>(std::lround(v));
      if (px < 0 || py < 0 || px >= width || py >= height) continue;
      float& target = depth.At(px, py);
      const float value = static_cast<float>(point.z());
      if (std::isfinite(value) && (target == 0 || value < target)) target = value;
    }
  }
  return depth;
}

}  // namespace

void SgbmOptions::Check() const {
  RequireOption(block_size >= 1 && block_size <= 11 && block_size % 2 == 1, "SgbmOptions.block_size", block_size,
                "odd, in [1, 11]");
  RequireOption(uniqueness_ratio >= 0 && uniqueness_ratio <= 100, "SgbmOptions.uniqueness_ratio",
                uniqueness_ratio, "[0, 100] (percent)");
  RequireOption(speckle_window >= 0, "SgbmOptions.speckle_window", speckle_window, ">= 0");
  RequireOption(speckle_range >= 0, "SgbmOptions.speckle_range", speckle_range, ">= 0");
}

namespace {

// The first of `plan`'s sources that rectifies to the right of its view, with the
// rectification; nullopt when none does.
std::optional<std::pair<const SparseImage*, RectifiedPair>> RightSource(const SparseModel& model, const ViewPlan& plan) {
  const SparseImage& reference = model.ImageById(plan.image_id);
  const Camera& camera = model.CameraById(reference.camera_id);
  for (uint32_t id : plan.sources) {
    const SparseImage& source = model.ImageById(id);
    if (std::optional<RectifiedPair> pair =
            Rectify(camera, reference.cam_from_world, model.CameraById(source.camera_id), source.cam_from_world)) {
      return std::pair{&source, std::move(*pair)};
    }
  }
  return std::nullopt;
}

// StereoSGBM's disparities of the rectified pair (left: the reference), in 1/16 pixel; its
// "no disparity" value, (min_disparity - 1) * 16, where a window cannot be trusted.
cv::Mat MatchPair(const cv::Mat& left_photo, const cv::Mat& right_photo, const Camera& camera,
                  const Camera& source_camera, const RectifiedPair& pair, int min_disparity, int num_disparities,
                  const SgbmOptions& options) {
  const cv::Size size = pair.size;
  cv::Mat map_x, map_y, left, right;
  cv::initUndistortRectifyMap(IntrinsicMatrix(camera), cv::noArray(), pair.r1, pair.p1, size, CV_32FC1, map_x,
                              map_y);
  cv::remap(left_photo, left, map_x, map_y, cv::INTER_LINEAR);
  const cv::Size photo_size(static_cast<int>(camera.width), static_cast<int>(camera.height));
  const cv::Mat matchable = MatchableMask(left, map_x, map_y, photo_size, options.block_size);
  cv::initUndistortRectifyMap(IntrinsicMatrix(source_camera), cv::noArray(), pair.r2, pair.p2, size, CV_32FC1,
                              map_x, map_y);
  cv::remap(right_photo, right, map_x, map_y, cv::INTER_LINEAR);
  const int block = options.block_size;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      min_disparity, num_disparities, block, 8 * block * block, 32 * block * block, 1, 0,
      options.uniqueness_ratio, options.speckle_window, options.speckle_range,
      cv::StereoSGBM::MODE_SGBM_3WAY);
  // StereoSGBM leaves the first min + num disparities columns unmatched: pad both images on
  // the left by that much and crop the padding off the disparities.
  const int pad = min_disparity + num_disparities;
  cv::copyMakeBorder(left, left, 0, 0, pad, 0, cv::BORDER_CONSTANT, 0);
  cv::copyMakeBorder(right, right, 0, 0, pad, 0, cv::BORDER_CONSTANT, 0);
  cv::Mat padded_disparity;
  sgbm->compute(left, right, padded_disparity);
  cv::Mat disparity = padded_disparity.colRange(pad, padded_disparity.cols);
  disparity.setTo(cv::Scalar((min_disparity - 1) * 16), ~matchable);
  return disparity;
}

}  // namespace

std::optional<SgbmViewDepth> SgbmStereoView(const SparseModel& model, const ViewPlan& plan,
                                            const std::function<Image(const SparseImage&)>& read_photo,
                                            const SgbmOptions& options) {
  const std::optional<std::pair<const SparseImage*, RectifiedPair>> found = RightSource(model, plan);
  if (!found) return std::nullopt;
  const auto& [source, pair] = *found;
  const SparseImage& reference = model.ImageById(plan.image_id);
  const Camera& camera = model.CameraById(reference.camera_id);
  int min_disparity = 0, num_disparities = 16;
  DisparityRange(pair, plan.min_depth, plan.max_depth, min_disparity, num_disparities);
  const cv::Mat left_photo = Gray8(read_photo(reference));
  const cv::Mat disparity = MatchPair(left_photo, Gray8(read_photo(*source)), camera,
                                      model.CameraById(source->camera_id), pair, min_disparity, num_disparities, options);
  SgbmViewDepth view;
  view.depth = DepthFromDisparity(disparity, pair, camera, min_disparity);
  view.confidence = DepthMap(view.depth.Width(), view.depth.Height());
  for (size_t p = 0; p < view.depth.Values().size(); ++p) {
    view.confidence.Values()[p] = view.depth.Values()[p] > 0 ? 1.0f : 0.0f;
  }
  view.report.name = plan.name;
  view.report.sources = {source->name};
  view.report.min_depth = plan.min_depth;
  view.report.max_depth = plan.max_depth;
  size_t valid = 0;
  for (float value : view.depth.Values()) valid += value > 0;
  view.report.geometric_share = view.report.photometric_share =
      static_cast<double>(valid) / static_cast<double>(view.depth.Values().size());
  return view;
}

}  // namespace parallax

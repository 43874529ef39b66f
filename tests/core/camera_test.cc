#include "core/camera.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

Camera MakeCamera(CameraModel model, std::vector<double> params) {
  Camera camera;
  camera.id = 1;
  camera.model = model;
  camera.width = 640;
  camera.height = 480;
  camera.params = std::move(params);
  camera.Check();
  return camera;
}

// One camera per supported model with moderate distortion.
std::vector<Camera> EveryModel() {
  return {
      MakeCamera(CameraModel::kSimplePinhole, {500, 320, 240}),
      MakeCamera(CameraModel::kPinhole, {510, 490, 321.5, 239.5}),
      MakeCamera(CameraModel::kSimpleRadial, {500, 320, 240, -0.12}),
      MakeCamera(CameraModel::kRadial, {500, 320, 240, -0.15, 0.03}),
      MakeCamera(CameraModel::kOpenCV, {505, 495, 318, 242, -0.2, 0.05, 0.001, -0.0015}),
  };
}

TEST(Camera, NamesAndIdsMatchColmap) {
  EXPECT_EQ(CameraModelName(CameraModel::kSimpleRadial), "SIMPLE_RADIAL");
  EXPECT_EQ(CameraModelNamed("OPENCV"), CameraModel::kOpenCV);
  EXPECT_EQ(CameraModelWithId(1), CameraModel::kPinhole);
  EXPECT_EQ(NumCameraParams(CameraModel::kOpenCV), 8);
  EXPECT_EQ(NumCameraParams(CameraModel::kFullOpenCV), 12);
  EXPECT_EQ(CameraModelNamed("PINHOLE2"), std::nullopt);
  EXPECT_EQ(CameraModelWithId(11), std::nullopt);
  EXPECT_EQ(CameraModelWithId(-1), std::nullopt);
  EXPECT_THROW(CameraModelName(static_cast<CameraModel>(11)), InternalError);
}

TEST(Camera, CheckRejectsWrongParameterCountsAndBadValues) {
  Camera camera = MakeCamera(CameraModel::kPinhole, {500, 500, 320, 240});
  EXPECT_EQ(camera.Problem(), "");
  camera.params.pop_back();
  EXPECT_EQ(camera.Problem(), "camera 1 (PINHOLE): expected 4 parameters, got 3");
  EXPECT_THROW(camera.Check(), InternalError);
  camera.params = {500, std::nan(""), 320, 240};
  EXPECT_THROW(camera.Check(), InternalError);
  camera.params = {-5, 500, 320, 240};
  EXPECT_THROW(camera.Check(), InternalError);
  camera.params = {500, 500, 320, 240};
  camera.width = 0;
  EXPECT_THROW(camera.Check(), InternalError);
}

TEST(Camera, ProjectUnprojectRoundTripsForEveryModel) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> pixel_x(0, 640), pixel_y(0, 480), depth(0.1, 100);
  for (const Camera& camera : EveryModel()) {
    SCOPED_TRACE(std::string(CameraModelName(camera.model)));
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector2d pixel(pixel_x(random), pixel_y(random));
      const double z = depth(random);
      const auto point = camera.Unproject(pixel, z);
      ASSERT_TRUE(point.has_value());
      EXPECT_NEAR(point->z(), z, 1e-12 * z);
      const auto reprojected = camera.Project(*point);
      ASSERT_TRUE(reprojected.has_value());
      EXPECT_LT((*reprojected - pixel).norm(), 1e-8);
    }
  }
}

TEST(Camera, DistortUndistortRoundTripsInsideTheInvertibleRange) {
  for (const Camera& camera : EveryModel()) {
    SCOPED_TRACE(std::string(CameraModelName(camera.model)));
    const double limit = std::min(camera.MaxInvertibleRadius(), 2.0) * 0.9;
    for (double radius = 0; radius < limit; radius += limit / 50) {
      for (double angle = 0; angle < 6.28; angle += 0.7) {
        const Eigen::Vector2d normalized(radius * std::cos(angle), radius * std::sin(angle));
        const auto undistorted = camera.Undistort(camera.Distort(normalized));
        ASSERT_TRUE(undistorted.has_value()) << "radius " << radius;
        EXPECT_LT((*undistorted - normalized).norm(), 1e-10) << "radius " << radius;
      }
    }
  }
}

TEST(Camera, UndistortReportsFailureBeyondTheInvertibleLimit) {
  // r (1 + k r^2) with k = -0.3 turns back at r = sqrt(1 / 0.9) = 1.054: distorted radii
  // above its peak, 0.703, have no preimage at all.
  const Camera camera = MakeCamera(CameraModel::kSimpleRadial, {500, 320, 240, -0.3});
  EXPECT_NEAR(camera.MaxInvertibleRadius(), std::sqrt(1 / 0.9), 1e-12);
  const double peak = camera.Distort({camera.MaxInvertibleRadius(), 0}).x();
  EXPECT_NEAR(peak, 0.7027, 1e-4);
  EXPECT_FALSE(camera.Undistort({peak * 1.01, 0}).has_value());
  EXPECT_FALSE(camera.Undistort({0, peak * 3}).has_value());
  // Just inside the limit the inverse is still found, on the monotonic branch.
  const auto inside = camera.Undistort({peak * 0.999, 0});
  ASSERT_TRUE(inside.has_value());
  EXPECT_LT(inside->norm(), camera.MaxInvertibleRadius());
  EXPECT_NEAR(camera.Distort(*inside).x(), peak * 0.999, 1e-12);
  // Points beyond the fold project nowhere rather than onto the wrong pixel.
  EXPECT_FALSE(camera.Project({1.2, 0, 1}).has_value());
}

TEST(Camera, UnprojectAtStronglyDistortedImageCornersIsFiniteOrReported) {
  const Camera camera = MakeCamera(CameraModel::kOpenCV, {300, 300, 320, 240, -0.35, 0.1, 0, 0});
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(640, 0),
                                       Eigen::Vector2d(0, 480), Eigen::Vector2d(640, 480)}) {
    const auto ray = camera.Unproject(corner);
    if (ray) {
      EXPECT_TRUE(ray->allFinite());
      EXPECT_LT((*camera.Project(*ray) - corner).norm(), 1e-8);
    }
  }
}

TEST(Camera, PointsAtOrBehindTheCameraAreRejected) {
  for (const Camera& camera : EveryModel()) {
    EXPECT_FALSE(camera.Project({0.1, 0.2, -1}).has_value());
    EXPECT_FALSE(camera.Project({0.1, 0.2, 0}).has_value());
    EXPECT_FALSE(camera.Project({0, 0, -0.0}).has_value());
    EXPECT_FALSE(camera.Project({std::nan(""), 0, 1}).has_value());
    EXPECT_FALSE(camera.Project({0, 0, std::numeric_limits<double>::infinity()}).has_value());
    EXPECT_FALSE(camera.Unproject({10, 10}, 0).has_value());
    EXPECT_FALSE(camera.Unproject({10, 10}, -2).has_value());
  }
}

TEST(Camera, ExtremeFocalLengthsRoundTrip) {
  for (const double focal : {1.0, 1e6}) {
    SCOPED_TRACE(focal);
    const Camera camera = MakeCamera(CameraModel::kSimpleRadial, {focal, 320, 240, 0.05});
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(320, 240),
                                        Eigen::Vector2d(639.5, 479.5)}) {
      const auto point = camera.Unproject(pixel, 3.0);
      if (focal == 1.0 && !point) continue;  // 640 px at f = 1 px is far past the fold.
      ASSERT_TRUE(point.has_value());
      const auto reprojected = camera.Project(*point);
      ASSERT_TRUE(reprojected.has_value());
      EXPECT_LT((*reprojected - pixel).norm(), 1e-6 * std::max(1.0, focal / 1e3));
    }
  }
  // f = 1 px, no distortion: every pixel is a valid ray, even at 90 degrees off-axis.
  const Camera wide = MakeCamera(CameraModel::kPinhole, {1, 1, 320, 240});
  const auto ray = wide.Unproject({639.5, 479.5});
  ASSERT_TRUE(ray.has_value());
  EXPECT_NEAR((*wide.Project(*ray) - Eigen::Vector2d(639.5, 479.5)).norm(), 0, 1e-9);
}

TEST(Camera, PixelCentresFollowColmapConvention) {
  const Camera camera = MakeCamera(CameraModel::kSimplePinhole, {100, 2, 2});
  // With the principal point at (2, 2) on a 4x4 image, the optical axis passes between the
  // centres of pixels 1 and 2, which lie at 1.5 and 2.5.
  const auto left = camera.Unproject({1.5, 1.5});
  const auto right = camera.Unproject({2.5, 2.5});
  EXPECT_NEAR(left->x(), -right->x(), 1e-15);
}

}  // namespace
}  // namespace parallax

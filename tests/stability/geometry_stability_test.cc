// Stiff and extreme geometry (issue: numerical stability): every case gives a finite, correct
// result or a clear refusal, never NaN, Inf or a silently wrong answer.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "core/camera.h"
#include "core/pose.h"

namespace parallax {
namespace {

Camera Radial(double focal, uint64_t width, uint64_t height, double k = -0.05) {
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = width;
  camera.height = height;
  camera.params = {focal, width / 2.0, height / 2.0, k};
  camera.Check();
  return camera;
}

TEST(GeometryStability, ProjectionAcrossTwentyOneOrdersOfDepthIsFiniteAndRoundTrips) {
  const Camera camera = Radial(500, 640, 480);
  for (const double depth : {1e-9, 1e-4, 1.0, 1e6, 1e12}) {
    SCOPED_TRACE(depth);
    // A point on the optical axis and one 0.1 rad off it, at this depth.
    for (const double offset : {0.0, 0.1}) {
      const Eigen::Vector3d point(offset * depth, -0.5 * offset * depth, depth);
      const auto pixel = camera.Project(point);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_TRUE(pixel->allFinite());
      const auto back = camera.Unproject(*pixel, depth);
      ASSERT_TRUE(back.has_value());
      EXPECT_LT((*back - point).norm(), 1e-9 * depth);
    }
  }
}

TEST(GeometryStability, PointsOnTheCameraPlaneOrBehindAreRefusedNotProjected) {
  const Camera camera = Radial(500, 640, 480);
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 0, -1e-12), Eigen::Vector3d(1, 2, -1e6),
        Eigen::Vector3d(1, 0, tiny), Eigen::Vector3d(1e300, 0, 1e-300)}) {
    const auto pixel = camera.Project(point);
    if (pixel) {
      EXPECT_TRUE(pixel->allFinite()) << point.transpose();
    }
  }
  EXPECT_FALSE(camera.Project({1, 1, 0}).has_value());
  EXPECT_FALSE(camera.Project({0, 0, -1e-12}).has_value());
  EXPECT_FALSE(camera.Project({1, 0, tiny}).has_value());  // 1/denorm overflows: refused.
}

TEST(GeometryStability, FocalLengthsFromOnePixelToAMillionRoundTrip) {
  for (const double focal : {1.0, 10.0, 1e3, 1e5, 1e6}) {
    SCOPED_TRACE(focal);
    const Camera camera = Radial(focal, 640, 480, 0.0);
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(639.5, 479.5),
                                         Eigen::Vector2d(320.25, 100.75)}) {
      const auto point = camera.Unproject(pixel, 7.0);
      ASSERT_TRUE(point.has_value());
      EXPECT_LT((*camera.Project(*point) - pixel).norm(), 1e-9 * std::max(1.0, 640 / focal));
    }
  }
}

TEST(GeometryStability, ExtremeImageSizesNeedNoPixelMemory) {
  // Cameras are parameters only: a 16384 x 16384 camera allocates nothing per pixel.
  for (const uint64_t size : {uint64_t{1}, uint64_t{16384}}) {
    const Camera camera = Radial(1.2 * size, size, size);
    const Eigen::Vector2d corner(size - 0.5, size - 0.5);
    const auto ray = camera.Unproject(corner);
    ASSERT_TRUE(ray.has_value());
    EXPECT_LT((*camera.Project(*ray) - corner).norm(), 1e-8 * size);
  }
}

TEST(GeometryStability, UndistortionAtStronglyDistortedCornersConvergesOrRefuses) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> k(-0.6, 0.6);
  for (int trial = 0; trial < 200; ++trial) {
    const Camera camera = Radial(300, 640, 480, k(random));
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(640, 480),
                                          Eigen::Vector2d(0, 480), Eigen::Vector2d(640, 0)}) {
      const auto ray = camera.Unproject(corner);
      if (!ray) continue;  // Beyond the invertible radius: refused, as documented.
      ASSERT_TRUE(ray->allFinite());
      const auto reprojected = camera.Project(*ray);
      ASSERT_TRUE(reprojected.has_value());
      EXPECT_LT((*reprojected - corner).norm(), 1e-6);
    }
  }
}

TEST(GeometryStability, QuaternionsNearIdentityAndHalfTurnKeepTheirAngle) {
  for (const double angle : {1e-12, 1e-8, 1e-4, std::numbers::pi - 1e-4, std::numbers::pi - 1e-8,
                             std::numbers::pi}) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Eigen::Vector3d(1, -2, 0.5).normalized()));
    const double degrees = angle * 180 / std::numbers::pi;
    EXPECT_NEAR(RotationAngleDeg(Eigen::Quaterniond::Identity(), q), degrees, 1e-9 * std::max(1.0, degrees));
  }
}

TEST(GeometryStability, NonNormalisedQuaternionsAreNormalisedOnConstruction) {
  for (const double scale : {1e-150, 1e-8, 3.0, 1e150}) {
    const Eigen::Quaterniond raw(0.5 * scale, -0.5 * scale, 0.5 * scale, 0.5 * scale);
    const Rigid3d pose(raw, Eigen::Vector3d(1, 2, 3));
    EXPECT_NEAR(pose.rotation.norm(), 1, 1e-15) << scale;
  }
}

TEST(GeometryStability, SlerpFloatPathAgreesWithLongDoubleReference) {
  // Worst relative error of Slerp's angle over random inputs against a long-double formula.
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  double worst = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Quaterniond a = Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random)).normalized();
    const Eigen::Quaterniond b = Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random)).normalized();
    const double t = std::uniform_real_distribution<double>(0, 1)(random);
    const double full = RotationAngleDeg(a, b);
    const double partial = RotationAngleDeg(a, Slerp(a, b, t));
    const long double expected = static_cast<long double>(full) * t;
    if (expected < 1e-6L) continue;
    worst = std::max(worst, static_cast<double>(std::abs(partial - expected) / expected));
  }
  EXPECT_LT(worst, 1e-9) << "worst relative error " << worst;
}

}  // namespace
}  // namespace parallax

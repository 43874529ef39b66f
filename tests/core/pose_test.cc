#include "core/pose.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/random_rotation.h"

namespace parallax {
namespace {

using test::RandomRotation;

TEST(Pose, CameraCenterMapsToTheOrigin) {
  std::mt19937 random(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d cam_from_world(RandomRotation(random), Eigen::Vector3d::Random() * 10);
    EXPECT_LT((cam_from_world * CameraCenter(cam_from_world)).norm(), 1e-12);
  }
}

TEST(Pose, ConstructorNormalisesAndRejectsZeroQuaternions) {
  const Rigid3d pose(Eigen::Quaterniond(2, 0, 0, 0), Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(pose.rotation.norm(), 1.0);
  EXPECT_THROW(Rigid3d(Eigen::Quaterniond(0, 0, 0, 0), Eigen::Vector3d::Zero()),
               InternalError);
  EXPECT_THROW(Rigid3d(Eigen::Quaterniond(std::nan(""), 0, 0, 0), Eigen::Vector3d::Zero()),
               InternalError);
}

TEST(Pose, InverseAndRelativePoseCompose) {
  std::mt19937 random(2);
  const Rigid3d a_from_world(RandomRotation(random), Eigen::Vector3d(1, -2, 3));
  const Rigid3d b_from_world(RandomRotation(random), Eigen::Vector3d(-4, 0.5, 2));
  const Rigid3d b_from_a = RelativePose(a_from_world, b_from_world);
  const Eigen::Vector3d point(0.3, -1.7, 5.2);
  EXPECT_LT((b_from_a * (a_from_world * point) - b_from_world * point).norm(), 1e-12);
  EXPECT_LT(((a_from_world * a_from_world.Inverse()) * point - point).norm(), 1e-12);
}

TEST(Pose, LookAtPointsTheOpticalAxisAtTheTargetWithImageUpAlongWorldUp) {
  const Eigen::Vector3d eye(4, -3, 2), target(0, 0, 0.5);
  const Rigid3d cam_from_world = LookAt(eye, target, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d target_in_cam = cam_from_world * target;
  EXPECT_NEAR(target_in_cam.x(), 0, 1e-12);
  EXPECT_NEAR(target_in_cam.y(), 0, 1e-12);
  EXPECT_NEAR(target_in_cam.z(), (target - eye).norm(), 1e-12);
  // A point above the target appears higher in the image (smaller y, since y points down).
  EXPECT_LT((cam_from_world * (target + Eigen::Vector3d::UnitZ())).y(), 0);
  EXPECT_LT((CameraCenter(cam_from_world) - eye).norm(), 1e-12);
  EXPECT_THROW(LookAt(eye, eye, Eigen::Vector3d::UnitZ()), InternalError);
  EXPECT_THROW(LookAt({0, 0, 5}, {0, 0, 0}, Eigen::Vector3d::UnitZ()), InternalError);
}

TEST(Pose, SlerpEndpointsAndMidpointAngle) {
  const Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond b(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationAngleDeg(Slerp(a, b, 0), a), 0, 1e-9);
  EXPECT_NEAR(RotationAngleDeg(Slerp(a, b, 1), b), 0, 1e-9);
  EXPECT_NEAR(RotationAngleDeg(a, Slerp(a, b, 0.25)), 0.3 * 180 / std::numbers::pi, 1e-9);
}

TEST(Pose, SlerpTakesTheShortArcBetweenAntipodalRepresentations) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond b(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond minus_b(-b.w(), -b.x(), -b.y(), -b.z());
  const Eigen::Quaterniond middle = Slerp(a, minus_b, 0.5);
  EXPECT_NEAR(RotationAngleDeg(middle, Eigen::Quaterniond(Eigen::AngleAxisd(
                                           0.5, Eigen::Vector3d::UnitX()))),
              0, 1e-9);
  // -q is q: slerp between them stays on that one rotation, with no division by zero.
  const Eigen::Quaterniond minus_a(-a.w(), -a.x(), -a.y(), -a.z());
  for (const double t : {0.0, 0.3, 0.5, 1.0}) {
    const Eigen::Quaterniond q = Slerp(a, minus_a, t);
    EXPECT_TRUE(q.coeffs().allFinite());
    EXPECT_NEAR(RotationAngleDeg(q, a), 0, 1e-9);
  }
}

TEST(Pose, SlerpOfNearlyEqualRotationsIsFiniteAndBetweenThem) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond b(Eigen::AngleAxisd(1.0 + 1e-12, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond q = Slerp(a, b, 0.5);
  EXPECT_TRUE(q.coeffs().allFinite());
  EXPECT_NEAR(q.norm(), 1, 1e-15);
  EXPECT_LT(RotationAngleDeg(q, a), 1e-9);
}

TEST(Pose, RotationAngleIsAccurateNearZeroAndNear180Degrees) {
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond tiny(Eigen::AngleAxisd(1e-9, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationAngleDeg(identity, tiny), 1e-9 * 180 / std::numbers::pi, 1e-20);
  const Eigen::Quaterniond half_turn(Eigen::AngleAxisd(std::numbers::pi - 1e-7,
                                                       Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(RotationAngleDeg(identity, half_turn), 180 - 1e-7 * 180 / std::numbers::pi,
              1e-9);
}

TEST(Pose, InterpolatePoseMovesTheCentreAlongTheSegment) {
  const Rigid3d a = LookAt({5, 0, 2}, {0, 0, 0}, Eigen::Vector3d::UnitZ());
  const Rigid3d b = LookAt({0, 5, 2}, {0, 0, 0}, Eigen::Vector3d::UnitZ());
  const Rigid3d middle = InterpolatePose(a, b, 0.5);
  EXPECT_LT((CameraCenter(middle) - Eigen::Vector3d(2.5, 2.5, 2)).norm(), 1e-12);
  EXPECT_NEAR(RotationAngleDeg(a.rotation, middle.rotation),
              RotationAngleDeg(middle.rotation, b.rotation), 1e-9);
}

TEST(Pose, CompositionDoesNotDriftOverAMillionSteps) {
  const Rigid3d step(Eigen::Quaterniond(Eigen::AngleAxisd(2 * std::numbers::pi / 1000,
                                                          Eigen::Vector3d(1, 2, 3).normalized())),
                     Eigen::Vector3d::Zero());
  Rigid3d chain;
  for (int i = 0; i < 1000000; ++i) chain = step * chain;
  // 1000 full turns: back to the identity up to accumulated rounding.
  EXPECT_NEAR(chain.rotation.norm(), 1, 1e-12);
  EXPECT_LT(RotationAngleDeg(chain.rotation, Eigen::Quaterniond::Identity()), 1e-6);
}

}  // namespace
}  // namespace parallax

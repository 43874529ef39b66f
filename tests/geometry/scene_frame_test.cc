#include "geometry/scene_frame.h"

#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

// `count` cameras 320x240 (f 280) on a circle of `radius` at `height` above the plane z = 0,
// all looking at `target`, image up towards +z.
std::vector<FrameCamera> Ring(int count, double radius, double height, const Eigen::Vector3d& target) {
  std::vector<FrameCamera> cameras;
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * std::numbers::pi * i / count;
    const Eigen::Vector3d eye = target + Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), height);
    cameras.push_back({MakePinholeCamera(1, 320, 240, 280, 280, 160, 120), LookAt(eye, target, Eigen::Vector3d::UnitZ())});
  }
  return cameras;
}

// `count` cameras a metre apart along x, all looking ahead along +x: a walk.
std::vector<FrameCamera> Walk(int count) {
  std::vector<FrameCamera> cameras;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d eye(i, 0, 1.5);
    cameras.push_back({MakePinholeCamera(1, 320, 240, 280, 280, 160, 120),
                       LookAt(eye, eye + Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ())});
  }
  return cameras;
}

TEST(LookedAtPoint, IsWhereConvergingAxesMeet) {
  const Eigen::Vector3d target(1, -2, 0.5);
  const std::optional<Eigen::Vector3d> point = LookedAtPoint(Ring(8, 5, 2, target));
  ASSERT_TRUE(point.has_value());
  EXPECT_LT((*point - target).norm(), 1e-9);
}

TEST(LookedAtPoint, IsNoneForParallelAxesOrFewerThanThreeCameras) {
  EXPECT_FALSE(LookedAtPoint(Walk(10)).has_value());
  // Axes a degree apart are as good as parallel (the least eigenvalue is about 3e-4 a camera).
  std::vector<FrameCamera> nearly = Walk(10);
  for (size_t i = 0; i < nearly.size(); ++i) {
    const double turn = (i % 2 ? 1.0 : -1.0) * std::numbers::pi / 180;
    nearly[i].cam_from_world.rotation =
        nearly[i].cam_from_world.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitY()));
  }
  EXPECT_FALSE(LookedAtPoint(nearly).has_value());
  EXPECT_FALSE(LookedAtPoint(Ring(2, 5, 2, Eigen::Vector3d::Zero())).has_value());
  EXPECT_TRUE(LookedAtPoint(Ring(3, 5, 2, Eigen::Vector3d::Zero())).has_value());
}

TEST(FitSceneFrame, CamerasAloneMakeTheRigTheyStandOn) {
  const Eigen::Vector3d target(0, 0, 0.5);
  const std::vector<FrameCamera> ring = Ring(8, 4, 3, target);
  const SceneFrame frame = FitSceneFrame({}, {}, ring);
  EXPECT_FALSE(frame.ground.has_value()) << "camera centres are not a ground";
  EXPECT_LT((frame.up - Eigen::Vector3d::UnitZ()).norm(), 1e-9) << "the cameras' up";
  ASSERT_TRUE(frame.rig.has_value());
  EXPECT_LT((frame.rig->target - target).norm(), 1e-9);
  EXPECT_NEAR(frame.rig->distance, 5, 1e-9);
  EXPECT_NEAR(frame.rig->elevation_deg, std::asin(3.0 / 5) * 180 / std::numbers::pi, 1e-9);
  // With the photos' own field of view, the orbit at a camera's azimuth stands where it stands.
  const Rigid3d pose = DefaultOrbitPose(frame, 0, std::nullopt, ring[0].camera);
  EXPECT_LT((CameraCenter(pose) - CameraCenter(ring[0].cam_from_world)).norm(), 1e-9);
  EXPECT_LT(RotationAngleDeg(pose.rotation, ring[0].cam_from_world.rotation), 1e-6);
}

// The documented fallback for cameras that look at no point: no rig; the orbit circles the
// focus box (here the box of the camera centres) at elevation 30, far enough to frame it.
TEST(FitSceneFrame, ParallelCamerasFallBackToTheFocusBox) {
  const std::vector<FrameCamera> walk = Walk(10);
  const SceneFrame frame = FitSceneFrame({}, {}, walk);
  EXPECT_FALSE(frame.rig.has_value());
  EXPECT_LT((frame.focus.center() - Eigen::Vector3f(4.5f, 0, 1.5f)).norm(), 1e-5f);
  const Orbit orbit = DefaultOrbit(frame, 90, std::nullopt, walk[0].camera);
  EXPECT_LT((orbit.target - Eigen::Vector3d(4.5, 0, 1.5)).norm(), 1e-5);
  EXPECT_EQ(orbit.elevation_deg, 30);
  EXPECT_GT(orbit.distance, 4.5);
  EXPECT_THROW(FitSceneFrame({}, {}, {}), InternalError);
}

TEST(FitSceneFrame, GroundOfACloudGivesUpAndFocus) {
  // A 10 m square of ground points and a 1 m column standing at (2, 1).
  std::vector<Eigen::Vector3f> cloud;
  for (int y = 0; y <= 100; ++y) {
    for (int x = 0; x <= 100; ++x) cloud.emplace_back(-5 + 0.1f * x, -5 + 0.1f * y, 0);
  }
  for (int i = 0; i < 2000; ++i) cloud.emplace_back(2 + 0.001f * (i % 10), 1 + 0.001f * (i / 10 % 10), 0.0005f * i);
  const SceneFrame frame = FitSceneFrame({}, cloud, Ring(8, 6, 2, Eigen::Vector3d(2, 1, 0.5)));
  ASSERT_TRUE(frame.ground.has_value());
  EXPECT_GT(frame.up.z(), 0.999);
  EXPECT_LT((frame.FocusCentre() - Eigen::Vector3f(2, 1, 0.5f)).norm(), 0.05f);
  ASSERT_TRUE(frame.rig.has_value());
  EXPECT_LT((frame.rig->target - Eigen::Vector3d(2, 1, 0.5)).norm(), 1e-9);
}

TEST(OrbitPose, AzimuthZeroLiesAlongWorldXAndLooksAtTheCentre) {
  const Eigen::Vector3d centre(1, 2, 3);
  const Rigid3d pose = OrbitPose(centre, Eigen::Vector3d::UnitZ(), 0, 0, 2);
  EXPECT_LT((CameraCenter(pose) - Eigen::Vector3d(3, 2, 3)).norm(), 1e-12);
  const Eigen::Vector3d centre_in_cam = pose * centre;
  EXPECT_NEAR(centre_in_cam.x(), 0, 1e-12);
  EXPECT_NEAR(centre_in_cam.y(), 0, 1e-12);
  EXPECT_NEAR(centre_in_cam.z(), 2, 1e-12);
  // Image up (-y) is world up.
  EXPECT_LT((pose.rotation.conjugate() * Eigen::Vector3d(0, -1, 0) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
}

}  // namespace
}  // namespace parallax

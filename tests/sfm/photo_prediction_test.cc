#include "sfm/photo_prediction.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

Camera TestCamera(double cx, double cy) {
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 640;
  camera.height = 480;
  camera.params = {500, cx, cy, -0.05};
  return camera;
}

Rigid3d Turned(const Rigid3d& pose, double degrees, const Eigen::Vector3d& axis, const Eigen::Vector3d& shift) {
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()));
  return Rigid3d(turn * pose.rotation, pose.translation + shift);
}

// 200 points 4-8 units in front of photo "b.png" (identity pose) and two photos 1 unit either
// side, every point observed in all three at its exact projection.
SparseModel ThreePhotos(const Camera& camera) {
  SparseModel model;
  model.AddCamera(camera);
  const std::vector<Rigid3d> poses = {Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
                                              Eigen::Vector3d(-1, 0, 0)),
                                      Rigid3d(),
                                      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY())),
                                              Eigen::Vector3d(1, 0, 0))};
  const std::vector<std::string> names = {"a.png", "b.png", "c.png"};
  std::vector<SparseImage> images(3);
  for (uint32_t i = 0; i < 3; ++i) {
    images[i].id = i + 1;
    images[i].name = names[i];
    images[i].camera_id = camera.id;
    images[i].cam_from_world = poses[i];
  }
  std::mt19937 random(7);
  std::uniform_real_distribution<double> lateral(-2, 2), depth(4, 8);
  for (uint64_t id = 1; id <= 200; ++id) {
    Point3D point;
    point.id = id;
    point.xyz = {lateral(random), 0.75 * lateral(random), depth(random)};
    for (SparseImage& image : images) {
      point.track.push_back({image.id, static_cast<uint32_t>(image.points2d.size())});
      image.points2d.push_back({*camera.Project(image.cam_from_world * point.xyz), id});
    }
    model.AddPoint3D(point);
  }
  for (SparseImage& image : images) model.AddImage(image);
  return model;
}

TEST(ResectPose, FindsThePoseFromAStartHalfADegreeOff) {
  const SparseModel model = ThreePhotos(TestCamera(320, 240));
  const SparseImage& image = *model.FindImageByName("c.png");
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (const Point2D& keypoint : image.points2d) {
    points.push_back(model.Point3DById(keypoint.point3d_id).xyz);
    pixels.push_back(keypoint.xy);
  }
  // One mismatch 40 px off: the Cauchy loss keeps it from pulling the pose.
  pixels[5] += Eigen::Vector2d(40, -30);
  const Rigid3d start = Turned(image.cam_from_world, 0.5, {1, 2, 0}, {0.05, -0.02, 0.03});
  const Rigid3d pose = ResectPose(model.CameraById(1), points, pixels, start, 1.0);
  EXPECT_LT(RotationAngleDeg(pose.rotation, image.cam_from_world.rotation), 1e-3);
  EXPECT_LT((pose.translation - image.cam_from_world.translation).norm(), 1e-4);
  // Fewer than three points: the start as it was.
  const Rigid3d unchanged = ResectPose(model.CameraById(1), {points[0], points[1]}, {pixels[0], pixels[1]}, start, 1);
  EXPECT_EQ(unchanged.translation, start.translation);
  EXPECT_THROW(ResectPose(model.CameraById(1), points, {}, start, 1), InternalError);
}

TEST(LeftOutPhotoError, ZeroForTheTrueModelAndClippedForAMismatch) {
  SparseModel raw = ThreePhotos(TestCamera(320, 240));
  // The left-out photo's start pose is off; its observations are exact.
  SparseImage& left_out = raw.MutableImages()[2];
  left_out.cam_from_world = Turned(left_out.cam_from_world, 0.3, {0, 1, 1}, {0.01, 0, 0});
  const LeftOutError exact = LeftOutPhotoError(raw, raw, {"c.png"}, 2.0);
  EXPECT_EQ(exact.observations, 200u);
  EXPECT_LT(exact.rms_px, 1e-4);
  // One keypoint 50 px off counts as 2 px: RMS sqrt(4 / 200).
  left_out.points2d[9].xy += Eigen::Vector2d(50, 0);
  EXPECT_NEAR(LeftOutPhotoError(raw, raw, {"c.png"}, 2.0).rms_px, std::sqrt(4.0 / 200), 1e-3);
  EXPECT_THROW(LeftOutPhotoError(raw, raw, {"d.png"}, 2.0), InternalError);
}

// A model whose principal point is 6 px off the photos' own: the left-out photo's pose turns to
// absorb most of it, but not all (the points lie at different depths and the lens distorts).
TEST(LeftOutPhotoError, AShiftedPrincipalPointPredictsWorse) {
  const SparseModel raw = ThreePhotos(TestCamera(320, 240));
  SparseModel shifted;
  shifted.AddCamera(TestCamera(326, 240));
  for (const Point3D& point : raw.Points3D()) shifted.AddPoint3D(point);
  const double error = LeftOutPhotoError(shifted, raw, {"a.png"}, 2.0).rms_px;
  EXPECT_GT(error, 0.01);
  EXPECT_LT(error, 1.0);
}

}  // namespace
}  // namespace parallax

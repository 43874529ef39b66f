#include "pipeline/camera_uncertainty.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

Eigen::Quaterniond Turn(double degrees, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()));
}

// Five photos a..e on an arc around the origin, looking at it, sharing one camera of focal
// length `focal`.
SparseModel ArcOfPhotos(double focal) {
  SparseModel model;
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 1000;
  camera.height = 500;
  camera.params = {focal, 500, 250, 0};
  model.AddCamera(camera);
  for (uint32_t i = 0; i < 5; ++i) {
    const double angle = (static_cast<double>(i) - 2) * 0.2;
    SparseImage image;
    image.id = i + 1;
    image.name = std::string(1, static_cast<char>('a' + i));
    image.camera_id = 1;
    image.cam_from_world = LookAt({5 * std::sin(angle), 0.3 * i, -5 * std::cos(angle)}, {0, 0, 0}, {0, -1, 0});
    model.AddImage(image);
  }
  return model;
}

// The whole model's five folds, each without one photo and in its own frame (turned, scaled
// and moved); photo c turned 0.1 degrees one way or the other in each, the focal length 2 px
// either side of the whole's.
std::vector<SparseModel> FoldsOf(const SparseModel& whole) {
  std::vector<SparseModel> folds;
  for (uint32_t left_out = 1; left_out <= 5; ++left_out) {
    const SparseModel shifted = ArcOfPhotos(800 + (left_out % 2 ? -2 : 2));
    // x_fold = 2 * R * x_whole + t, so cam_from_fold = cam_from_whole * whole_from_fold.
    const Eigen::Quaterniond rotation = Turn(30, {1, 2, 3});
    const Eigen::Vector3d translation(4, -1, 2);
    SparseModel fold;
    fold.AddCamera(shifted.Cameras().front());
    for (SparseImage image : shifted.Images()) {
      if (image.id == left_out) continue;
      const Eigen::Quaterniond turned =
          image.name == "c" ? Turn(left_out % 2 ? 0.1 : -0.1, {0, 1, 0}) * image.cam_from_world.rotation
                            : image.cam_from_world.rotation;
      const Eigen::Vector3d centre = 2 * (rotation * CameraCenter(image.cam_from_world)) + translation;
      const Eigen::Quaterniond cam_from_fold = turned * rotation.inverse();
      image.cam_from_world = Rigid3d(cam_from_fold, -(cam_from_fold * centre));
      fold.AddImage(image);
    }
    folds.push_back(fold);
  }
  return folds;
}

TEST(JackknifeUncertainty, FindsThePhotoThatMovesFromFoldToFold) {
  const SparseModel whole = ArcOfPhotos(800);
  const CameraUncertainty uncertainty = JackknifeUncertainty(whole, FoldsOf(whole));
  EXPECT_EQ(uncertainty.folds, 5);
  // Focal lengths 798, 802, 798, 802, 798: sqrt(4/5 * (3 * 1.6^2 + 2 * 2.4^2)) = 3.919 px.
  EXPECT_NEAR(uncertainty.focal_px, 3.919, 1e-3);
  EXPECT_NEAR(uncertainty.principal_point_px, 0, 1e-9);
  ASSERT_EQ(uncertainty.rotation_deg.size(), 5u);
  // c, in four folds at +-0.1 degrees: sqrt(4/5 * 4 * 0.01) = 0.179 (the alignment, which c
  // pulls a little, takes some of it).
  for (const auto& [name, deg] : uncertainty.rotation_deg) {
    if (name == "c") {
      EXPECT_NEAR(deg, 0.179, 0.04);
    } else {
      EXPECT_LT(deg, 0.05) << name;
    }
  }
  EXPECT_THROW(JackknifeUncertainty(whole, {whole}), InternalError);
}

TEST(CameraUncertainty, WrittenAndReadBack) {
  const TempDir dir;
  const SparseModel whole = ArcOfPhotos(800);
  const CameraUncertainty uncertainty = JackknifeUncertainty(whole, FoldsOf(whole));
  const auto path = dir.Path() / "uncertainty.json";
  WriteCameraUncertainty(uncertainty, path);
  const CameraUncertainty read = ReadCameraUncertainty(path);
  EXPECT_EQ(read.folds, 5);
  EXPECT_DOUBLE_EQ(read.focal_px, uncertainty.focal_px);
  EXPECT_EQ(read.rotation_deg, uncertainty.rotation_deg);
  const nlohmann::json json = ToJson(uncertainty);
  EXPECT_EQ(json["rotation_deg"]["max_photo"], "c");
  EXPECT_NE(Describe(uncertainty).find("at most (c)"), std::string::npos) << Describe(uncertainty);
  WriteFileAtomically(path, "{\"folds\": 5}");
  try {
    ReadCameraUncertainty(path);
    ADD_FAILURE() << "no error for a file without the fields";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace parallax

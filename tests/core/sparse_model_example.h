#pragma once
// The example model the sparse model tests write and read (sparse_model_test.cc,
// sparse_model_errors_test.cc), and the files they write by hand.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "core/sparse_model.h"
#include "tests/temp_dir.h"

namespace parallax::sparse_model_example {
namespace fs = std::filesystem;

constexpr uint64_t kBigPointId = (uint64_t{1} << 33) + 5;  // Beyond uint32, as COLMAP allows.

inline void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary);
  file << text;
}

inline Camera MakeCamera(uint32_t id, CameraModel model, uint64_t width, uint64_t height,
                         std::vector<double> params) {
  Camera camera;
  camera.id = id;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  return camera;
}

inline SparseImage MakeImage(uint32_t id, uint32_t camera_id, std::string name,
                             const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation,
                             const std::vector<std::pair<Eigen::Vector2d, uint64_t>>& points) {
  SparseImage image;
  image.id = id;
  image.camera_id = camera_id;
  image.name = std::move(name);
  // Set directly: the Rigid3d constructor would renormalise.
  image.cam_from_world.rotation = rotation;
  image.cam_from_world.translation = translation;
  for (const auto& [xy, point3d_id] : points) image.points2d.push_back({xy, point3d_id});
  return image;
}

// Three camera models, images with valid and invalid 2D points (one with none, in the middle,
// so its empty line is followed by another image), 3D points out of id order, one with an empty
// track and one with an id beyond uint32. Quaternions are built from 0, +-0.5 and +-1 so that
// COLMAP's renormalisation leaves them bit for bit unchanged; other values use all 17 digits.
inline SparseModel MakeModel() {
  SparseModel model;
  model.AddCamera(MakeCamera(7, CameraModel::kOpenCV, 800, 600,
                             {600.5, 601.25, 400.125, 300.0625, 0.01, -0.002, 1e-4, -3e-5}));
  model.AddCamera(
      MakeCamera(1, CameraModel::kSimpleRadial, 640, 480, {1000.0 / 3, 320.5, 240.25, -0.0123}));
  model.AddCamera(MakeCamera(2, CameraModel::kPinhole, 1920, 1080,
                             {1234.5678901234567, 1234.0 / 7, 960.0, 540.5}));

  const uint64_t none = kInvalidPoint3DId;
  std::vector<SparseImage> images = {
      MakeImage(2, 2, "dir/b.png", Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5),
                Eigen::Vector3d(1.0 / 3, 2.0 / 3, -1e-3),
                {{{10.5, 20.25}, 4},
                 {{1.0 / 7, 1e-9}, 1},
                 {{3, 4}, none},
                 {{5.5, 6}, kBigPointId}}),
      MakeImage(1, 1, "a.jpg", Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(0.1, -0.2, 0.3),
                {{{100.125, 200.0 / 3}, 1}, {{0, 0}, none}, {{639.75, 479.5}, 4}, {{-1, 2}, none}}),
      MakeImage(5, 7, "c.jpg", Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5),
                Eigen::Vector3d(-2.5e7, 0, 1e-12), {}),
      MakeImage(9, 1, "d.jpg", Eigen::Quaterniond(0, 0, 0, 1), Eigen::Vector3d(5, 6, 7),
                {{{1.5, 2.5}, 10}, {{3.25, 4.75}, none}, {{2.0 / 3, 5.0 / 9}, 1}}),
  };

  // Tracks are derived from the images' references, as COLMAP keeps them consistent.
  std::vector<Point3D> points(5);
  const uint64_t ids[] = {4, 1, kBigPointId, 10, 12};
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].id = ids[i];
    points[i].xyz = Eigen::Vector3d(0.1 * static_cast<double>(i) + 1.0 / 3, -2.0 / 7, 1e5 / 3);
    points[i].rgb = Eigen::Matrix<uint8_t, 3, 1>(255, static_cast<uint8_t>(17 * i), 0);
    points[i].error = i == 0 ? -1 : 0.1 * static_cast<double>(i) / 3;
  }
  for (const SparseImage& image : images) {
    for (size_t k = 0; k < image.points2d.size(); ++k) {
      for (Point3D& point : points) {
        if (point.id == image.points2d[k].point3d_id) {
          point.track.push_back({image.id, static_cast<uint32_t>(k)});
        }
      }
    }
  }
  for (SparseImage& image : images) model.AddImage(std::move(image));
  for (Point3D& point : points) model.AddPoint3D(std::move(point));
  return model;
}

// A text model folder with the given cameras.txt and images.txt and an empty points3D.txt.
inline fs::path WriteTextModel(const TempDir& dir, const std::string& cameras,
                               const std::string& images) {
  const fs::path model = dir.Path() / "model";
  fs::create_directories(model);
  WriteFile(model / "cameras.txt", cameras);
  WriteFile(model / "images.txt", images);
  WriteFile(model / "points3D.txt", "");
  return model;
}

}  // namespace parallax::sparse_model_example

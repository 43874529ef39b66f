#pragma once
// COLMAP sparse models (cameras, images with their 2D points, points3D with tracks), read and
// written in COLMAP's TEXT and BINARY formats.
//
// Entries keep the order they were read in, so a binary model read and written again is byte
// for byte the same file (COLMAP writes its hash maps in no particular order). Text is written
// with 17 significant digits, so a text round trip is value-exact.
//
// Readers throw BadInputError naming the file and what is wrong (truncated data, wrong counts,
// unknown camera model, an image referring to a missing camera, ...).
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/pose.h"

namespace parallax {

inline constexpr uint64_t kInvalidPoint3DId = std::numeric_limits<uint64_t>::max();

struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // Pixels.
  uint64_t point3d_id = kInvalidPoint3DId;
};

struct SparseImage {
  uint32_t id = 0;
  Rigid3d cam_from_world;
  uint32_t camera_id = 0;
  std::string name;
  std::vector<Point2D> points2d;
};

struct TrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_idx = 0;
};

struct Point3D {
  uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Matrix<uint8_t, 3, 1> rgb = Eigen::Matrix<uint8_t, 3, 1>::Zero();
  double error = -1;  // Mean reprojection error in pixels; -1 when unknown.
  std::vector<TrackElement> track;
};

enum class SparseFormat { kText, kBinary };

class SparseModel {
 public:
  // Adding an entry whose id is already present throws InternalError: readers check Has*.
  void AddCamera(Camera camera);
  void AddImage(SparseImage image);
  void AddPoint3D(Point3D point);
  bool HasCamera(uint32_t id) const { return camera_index_.contains(id); }
  bool HasImage(uint32_t id) const { return image_index_.contains(id); }
  bool HasPoint3D(uint64_t id) const { return point3d_index_.contains(id); }

  const std::vector<Camera>& Cameras() const { return cameras_; }
  const std::vector<SparseImage>& Images() const { return images_; }
  const std::vector<Point3D>& Points3D() const { return points3d_; }
  std::vector<SparseImage>& MutableImages() { return images_; }

  // Lookups by id; throw std::out_of_range naming the id when absent.
  const Camera& CameraById(uint32_t id) const;
  const SparseImage& ImageById(uint32_t id) const;
  const Point3D& Point3DById(uint64_t id) const;
  // The image with this name, or nullptr.
  const SparseImage* FindImageByName(const std::string& name) const;

 private:
  std::vector<Camera> cameras_;
  std::vector<SparseImage> images_;
  std::vector<Point3D> points3d_;
  std::unordered_map<uint32_t, size_t> camera_index_;
  std::unordered_map<uint32_t, size_t> image_index_;
  std::unordered_map<uint64_t, size_t> point3d_index_;
};

// Which format a folder holds: binary when cameras.bin, images.bin and points3D.bin are there,
// else text when the three .txt files are; std::nullopt when neither is complete.
std::optional<SparseFormat> DetectSparseFormat(const std::filesystem::path& dir);

// Reads a model folder in the format it holds (binary preferred). A missing points3D file is
// an error; an empty one is a model without points. Throws BadInputError.
SparseModel ReadSparseModel(const std::filesystem::path& dir);
SparseModel ReadSparseModel(const std::filesystem::path& dir, SparseFormat format);

// The model without each image's 2D points (all its keypoints: most of the model's memory once
// there are hundreds of photos), for the dense stages, which need the cameras, poses and tracks
// only. The tracks' point2d_idx then index nothing.
SparseModel ReadSparseModelWithoutKeypoints(const std::filesystem::path& dir);

// The images of `model` whose names are in `names` (or, with `keep` false, those whose names are
// not), the cameras they use, and the points they still observe from two or more of them; the
// other points' observations are cleared, so that colmap reads the model as whole.
SparseModel SelectImages(const SparseModel& model, const std::set<std::string>& names, bool keep);

// `model`'s cameras and images, without points and keypoints.
SparseModel CamerasAndPoses(const SparseModel& model);

// Writes cameras, images and points3D in `format` into `dir` (created if missing). Each file is
// written to a temporary name and renamed. Throws BadInputError if `dir` is not writable,
// InternalError for a model the readers would refuse (a non-finite pose, say).
void WriteSparseModel(const SparseModel& model, const std::filesystem::path& dir,
                      SparseFormat format);

}  // namespace parallax

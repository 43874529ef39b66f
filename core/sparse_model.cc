#include "core/sparse_model.h"

#include <cmath>
#include <stdexcept>
#include <system_error>
#include <unordered_set>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/sparse_model_formats.h"

namespace parallax {
namespace fs = std::filesystem;

namespace sparse_formats {

// COLMAP's "mean observations per image" and "mean track length" header values: both count
// the 2D points with a 3D point.
uint64_t NumObservations(const SparseModel& model) {
  uint64_t count = 0;
  for (const SparseImage& image : model.Images()) {
    for (const Point2D& point : image.points2d) count += point.point3d_id != kInvalidPoint3DId;
  }
  return count;
}

}  // namespace sparse_formats

namespace {

bool AllFinite(const auto& values) { return values.allFinite(); }

// ---------------------------------------------------------------------------------------------
// Checks shared by readers and writers, so that we never write a model we would refuse to read.

// A description of the first broken reference, or std::nullopt. Images must use existing
// cameras; 2D points must point at existing 3D points; tracks must point at existing images and
// at 2D points that point back at the same 3D point. Downstream code indexes with these ids, so
// a dangling one must stop here.
std::optional<std::string> FindBrokenReference(const SparseModel& model) {
  std::unordered_map<uint32_t, const SparseImage*> images;
  std::unordered_map<uint64_t, const Point3D*> points;
  images.reserve(model.Images().size());
  points.reserve(model.Points3D().size());
  for (const SparseImage& image : model.Images()) {
    // Ids can only collide after edits through MutableImages().
    if (!images.emplace(image.id, &image).second) {
      return "duplicate image id " + std::to_string(image.id);
    }
  }
  for (const Point3D& point : model.Points3D()) points.emplace(point.id, &point);

  for (const SparseImage& image : model.Images()) {
    if (!model.HasCamera(image.camera_id)) {
      return "image " + std::to_string(image.id) + " refers to camera " +
             std::to_string(image.camera_id) + ", which does not exist";
    }
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      const uint64_t point_id = image.points2d[i].point3d_id;
      if (point_id != kInvalidPoint3DId && points.count(point_id) == 0) {
        return "image " + std::to_string(image.id) + " point " + std::to_string(i) +
               " refers to 3D point " + std::to_string(point_id) + ", which does not exist";
      }
    }
  }
  for (const Point3D& point : model.Points3D()) {
    for (const TrackElement& element : point.track) {
      // Formatted only on failure: there are millions of track elements.
      auto where = [&] {
        return "3D point " + std::to_string(point.id) + " track element (" +
               std::to_string(element.image_id) + ", " + std::to_string(element.point2d_idx) +
               ")";
      };
      const auto image = images.find(element.image_id);
      if (image == images.end()) return where() + " refers to a missing image";
      const std::vector<Point2D>& points2d = image->second->points2d;
      if (element.point2d_idx >= points2d.size()) {
        return where() + " is beyond the image's " + std::to_string(points2d.size()) +
               " 2D points";
      }
      if (points2d[element.point2d_idx].point3d_id != point.id) {
        return where() + " refers to a 2D point that does not refer back to it";
      }
    }
  }
  return std::nullopt;
}

// Refuses (InternalError) what the readers would refuse, so a written model can always be read
// back.
void CheckWritable(const SparseModel& model, SparseFormat format) {
  auto fail = [](const std::string& what) { throw InternalError("cannot write sparse model: " + what); };
  for (const Camera& camera : model.Cameras()) {
    if (std::string problem = camera.Problem(); !problem.empty()) fail(problem);
  }
  for (const SparseImage& image : model.Images()) {
    const std::string where = "image " + std::to_string(image.id) + " ";
    const Rigid3d& pose = image.cam_from_world;
    if (!AllFinite(pose.rotation.coeffs()) || pose.rotation.squaredNorm() == 0 ||
        !AllFinite(pose.translation)) {
      fail(where + "has a non-finite or zero pose");
    }
    const bool name_fits = format == SparseFormat::kText
                               ? sparse_formats::IsTextSafeName(image.name)
                               : image.name.find('\0') == std::string::npos;
    if (!name_fits) fail(where + "name '" + image.name + "' cannot be stored in this format");
    for (const Point2D& point : image.points2d) {
      if (!AllFinite(point.xy)) fail(where + "has a non-finite 2D point");
    }
  }
  for (const Point3D& point : model.Points3D()) {
    if (!AllFinite(point.xyz) || !std::isfinite(point.error)) {
      fail("3D point " + std::to_string(point.id) + " has a non-finite value");
    }
  }
  if (const auto broken = FindBrokenReference(model)) fail(*broken);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// SparseModel.

void SparseModel::AddCamera(Camera camera) {
  if (!camera_index_.emplace(camera.id, cameras_.size()).second) {
    throw InternalError("duplicate camera id " + std::to_string(camera.id));
  }
  cameras_.push_back(std::move(camera));
}

void SparseModel::AddImage(SparseImage image) {
  if (!image_index_.emplace(image.id, images_.size()).second) {
    throw InternalError("duplicate image id " + std::to_string(image.id));
  }
  images_.push_back(std::move(image));
}

void SparseModel::AddPoint3D(Point3D point) {
  if (!point3d_index_.emplace(point.id, points3d_.size()).second) {
    throw InternalError("duplicate 3D point id " + std::to_string(point.id));
  }
  points3d_.push_back(std::move(point));
}

const Camera& SparseModel::CameraById(uint32_t id) const {
  const auto it = camera_index_.find(id);
  if (it == camera_index_.end()) throw std::out_of_range("no camera with id " + std::to_string(id));
  return cameras_[it->second];
}

const SparseImage& SparseModel::ImageById(uint32_t id) const {
  const auto it = image_index_.find(id);
  // MutableImages() lets callers edit entries behind the index; verify before trusting it.
  if (it != image_index_.end() && it->second < images_.size() && images_[it->second].id == id) {
    return images_[it->second];
  }
  for (const SparseImage& image : images_) {
    if (image.id == id) return image;
  }
  throw std::out_of_range("no image with id " + std::to_string(id));
}

const Point3D& SparseModel::Point3DById(uint64_t id) const {
  const auto it = point3d_index_.find(id);
  if (it == point3d_index_.end()) {
    throw std::out_of_range("no 3D point with id " + std::to_string(id));
  }
  return points3d_[it->second];
}

const SparseImage* SparseModel::FindImageByName(const std::string& name) const {
  for (const SparseImage& image : images_) {
    if (image.name == name) return &image;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Folders.

std::optional<SparseFormat> DetectSparseFormat(const fs::path& dir) {
  auto all_exist = [&dir](const char* extension) {
    std::error_code error;
    for (const char* stem : {"cameras", "images", "points3D"}) {
      if (!fs::is_regular_file(dir / (std::string(stem) + extension), error)) return false;
    }
    return true;
  };
  if (all_exist(".bin")) return SparseFormat::kBinary;
  if (all_exist(".txt")) return SparseFormat::kText;
  return std::nullopt;
}

SparseModel ReadSparseModel(const fs::path& dir) {
  const std::optional<SparseFormat> format = DetectSparseFormat(dir);
  if (!format) {
    throw BadInputError(dir.string() + ": no COLMAP sparse model (needs cameras, images and "
                        "points3D, all .bin or all .txt)");
  }
  return ReadSparseModel(dir, *format);
}

SparseModel ReadSparseModel(const fs::path& dir, SparseFormat format) {
  SparseModel model;
  const bool binary = format == SparseFormat::kBinary;
  const std::string extension = binary ? ".bin" : ".txt";
  // Cameras first: images are checked against them as they are read.
  if (binary) {
    sparse_formats::ReadCamerasBinary(dir / "cameras.bin", &model);
    sparse_formats::ReadImagesBinary(dir / "images.bin", &model);
    sparse_formats::ReadPoints3DBinary(dir / "points3D.bin", &model);
  } else {
    sparse_formats::ReadCamerasText(dir / "cameras.txt", &model);
    sparse_formats::ReadImagesText(dir / "images.txt", &model);
    sparse_formats::ReadPoints3DText(dir / "points3D.txt", &model);
  }
  if (const auto broken = FindBrokenReference(model)) {
    throw BadInputError((dir / ("images" + extension)).string() + " and points3D" + extension +
                        " disagree: " + *broken);
  }
  return model;
}

SparseModel ReadSparseModelWithoutKeypoints(const fs::path& dir) {
  SparseModel model = ReadSparseModel(dir);
  for (SparseImage& image : model.MutableImages()) std::vector<Point2D>().swap(image.points2d);
  ReturnFreedMemory();  // Else the keypoints' pages stay resident through the stage that reads it.
  return model;
}

namespace {

// `image` with its observations of points other than `points` cleared (its keypoints stay).
SparseImage ObservingOnly(SparseImage image, const std::unordered_set<uint64_t>& points) {
  for (Point2D& point : image.points2d) {
    if (!points.count(point.point3d_id)) point.point3d_id = kInvalidPoint3DId;
  }
  return image;
}

}  // namespace

SparseModel SelectImages(const SparseModel& model, const std::set<std::string>& names, bool keep) {
  std::unordered_set<uint32_t> images, cameras;
  for (const SparseImage& image : model.Images()) {
    if ((names.count(image.name) != 0) == keep) {
      images.insert(image.id);
      cameras.insert(image.camera_id);
    }
  }
  SparseModel selected;
  for (const Camera& camera : model.Cameras()) {
    if (cameras.count(camera.id)) selected.AddCamera(camera);
  }
  std::unordered_set<uint64_t> points;
  for (const Point3D& point : model.Points3D()) {
    Point3D kept = point;
    std::erase_if(kept.track, [&images](const TrackElement& element) { return !images.count(element.image_id); });
    if (kept.track.size() < 2) continue;
    points.insert(kept.id);
    selected.AddPoint3D(std::move(kept));
  }
  for (const SparseImage& image : model.Images()) {
    if (images.count(image.id)) selected.AddImage(ObservingOnly(image, points));
  }
  return selected;
}

SparseModel CamerasAndPoses(const SparseModel& model) {
  SparseModel cameras;
  for (const Camera& camera : model.Cameras()) cameras.AddCamera(camera);
  for (SparseImage image : model.Images()) {
    image.points2d.clear();
    cameras.AddImage(std::move(image));
  }
  return cameras;
}

void WriteSparseModel(const SparseModel& model, const fs::path& dir, SparseFormat format) {
  CheckWritable(model, format);
  if (format == SparseFormat::kBinary) {
    WriteFileAtomically(dir / "cameras.bin", sparse_formats::CamerasBinary(model));
    WriteFileAtomically(dir / "images.bin", sparse_formats::ImagesBinary(model));
    WriteFileAtomically(dir / "points3D.bin", sparse_formats::Points3DBinary(model));
  } else {
    WriteFileAtomically(dir / "cameras.txt", sparse_formats::CamerasText(model));
    WriteFileAtomically(dir / "images.txt", sparse_formats::ImagesText(model));
    WriteFileAtomically(dir / "points3D.txt", sparse_formats::Points3DText(model));
  }
}

}  // namespace parallax

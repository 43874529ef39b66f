// COLMAP's binary sparse-model format: cameras.bin, images.bin, points3D.bin.
#include <bit>
#include <cmath>
#include <cstring>
#include <string_view>
#include <type_traits>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/sparse_model_formats.h"

namespace parallax::sparse_formats {
namespace fs = std::filesystem;

// The binary files are little-endian; reading and writing them by memcpy is only right on a
// little-endian host, which every platform we build for is.
static_assert(std::endian::native == std::endian::little);

namespace {

// Smallest encodings of one entry, to reject counts a file cannot hold before reserving.
constexpr uint64_t kMinCameraBytes = 4 + 4 + 8 + 8;
constexpr uint64_t kMinImageBytes = 4 + 7 * 8 + 4 + 1 + 8;
constexpr uint64_t kPoint2DBytes = 8 + 8 + 8;
constexpr uint64_t kMinPoint3DBytes = 8 + 3 * 8 + 3 + 8 + 8;
constexpr uint64_t kTrackElementBytes = 4 + 4;

// ---------------------------------------------------------------------------------------------
// Binary reading.

// A cursor over a whole file in memory. The entry being read is kept as (kind, index, count)
// and formatted only when an error is thrown, as models have millions of entries.
class ByteReader {
 public:
  ByteReader(std::string_view bytes, const fs::path& path) : bytes_(bytes), file_(path.string()) {}

  void SetEntry(const char* kind, uint64_t index, uint64_t count) {
    kind_ = kind, index_ = index, count_ = count;
  }

  template <typename T>
  T Read() {
    static_assert(std::is_trivially_copyable_v<T>);
    Need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  double ReadFinite(const char* field) {
    const double value = Read<double>();
    if (!std::isfinite(value)) Fail(std::string("non-finite ") + field);
    return value;
  }

  std::string ReadNulTerminated() {
    const size_t end = bytes_.find('\0', pos_);
    if (end == std::string_view::npos) Fail("name has no terminating NUL before the end of file");
    std::string text(bytes_.substr(pos_, end - pos_));
    pos_ = end + 1;
    return text;
  }

  // A uint64 count of entries of at least `min_entry_bytes` each; a count the remaining bytes
  // cannot hold is refused here, before anyone reserves memory for it.
  uint64_t ReadCount(uint64_t min_entry_bytes, const char* what) {
    const uint64_t count = Read<uint64_t>();
    if (count > Remaining() / min_entry_bytes) {
      Fail(std::to_string(count) + " " + what + " need at least " +
           std::to_string(min_entry_bytes) + " bytes each, but only " +
           std::to_string(Remaining()) + " bytes are left");
    }
    return count;
  }

  void ExpectEnd() {
    kind_ = nullptr;
    if (Remaining() != 0) {
      Fail(std::to_string(Remaining()) + " unexpected bytes after the last entry");
    }
  }

  [[noreturn]] void Fail(const std::string& what) const {
    const std::string entry = Entry();
    throw BadInputError(file_ + ": " + (entry.empty() ? "" : entry + ": ") + what);
  }

 private:
  uint64_t Remaining() const { return bytes_.size() - pos_; }

  void Need(size_t size) const {
    if (Remaining() >= size) return;
    const std::string entry = Entry();
    throw BadInputError(file_ + ": truncated" + (entry.empty() ? "" : " in " + entry) +
                        " (needed " + std::to_string(size) + " bytes, " +
                        std::to_string(Remaining()) + " left)");
  }

  // "image 3 of 10" (counted from 1), or "" outside entries.
  std::string Entry() const {
    if (kind_ == nullptr) return "";
    return std::string(kind_) + " " + std::to_string(index_ + 1) + " of " +
           std::to_string(count_);
  }

  std::string_view bytes_;
  std::string file_;
  size_t pos_ = 0;
  const char* kind_ = nullptr;
  uint64_t index_ = 0;
  uint64_t count_ = 0;
};

}  // namespace

void ReadCamerasBinary(const fs::path& path, SparseModel* model) {
  const std::string bytes = ReadFileBytes(path);
  ByteReader reader(bytes, path);
  const uint64_t count = reader.ReadCount(kMinCameraBytes, "cameras");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetEntry("camera", i, count);
    Camera camera;
    camera.id = reader.Read<uint32_t>();
    const int32_t model_id = reader.Read<int32_t>();
    const std::optional<CameraModel> camera_model = CameraModelWithId(model_id);
    if (!camera_model) reader.Fail("unknown camera model id " + std::to_string(model_id));
    camera.model = *camera_model;
    camera.width = reader.Read<uint64_t>();
    camera.height = reader.Read<uint64_t>();
    camera.params.resize(NumCameraParams(camera.model));
    for (double& param : camera.params) param = reader.Read<double>();
    if (std::string problem = camera.Problem(); !problem.empty()) reader.Fail(problem);
    if (model->HasCamera(camera.id)) reader.Fail("duplicate camera id " + std::to_string(camera.id));
    model->AddCamera(std::move(camera));
  }
  reader.ExpectEnd();
}

void ReadImagesBinary(const fs::path& path, SparseModel* model) {
  const std::string bytes = ReadFileBytes(path);
  ByteReader reader(bytes, path);
  const uint64_t count = reader.ReadCount(kMinImageBytes, "images");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetEntry("image", i, count);
    SparseImage image;
    image.id = reader.Read<uint32_t>();
    // Members set directly: Rigid3d's constructor would renormalise, and the values must come
    // back out bit for bit.
    const double qw = reader.ReadFinite("QW"), qx = reader.ReadFinite("QX");
    const double qy = reader.ReadFinite("QY"), qz = reader.ReadFinite("QZ");
    image.cam_from_world.rotation = Eigen::Quaterniond(qw, qx, qy, qz);
    if (image.cam_from_world.rotation.squaredNorm() == 0) reader.Fail("zero quaternion");
    for (const int k : {0, 1, 2}) {
      image.cam_from_world.translation[k] = reader.ReadFinite(k == 0 ? "TX" : k == 1 ? "TY" : "TZ");
    }
    image.camera_id = reader.Read<uint32_t>();
    if (!model->HasCamera(image.camera_id)) {
      reader.Fail("camera id " + std::to_string(image.camera_id) + " is not in cameras.bin");
    }
    image.name = reader.ReadNulTerminated();
    const uint64_t num_points = reader.ReadCount(kPoint2DBytes, "2D points");
    image.points2d.resize(num_points);
    for (Point2D& point : image.points2d) {
      point.xy.x() = reader.ReadFinite("2D point x");
      point.xy.y() = reader.ReadFinite("2D point y");
      point.point3d_id = reader.Read<uint64_t>();
    }
    if (model->HasImage(image.id)) reader.Fail("duplicate image id " + std::to_string(image.id));
    model->AddImage(std::move(image));
  }
  reader.ExpectEnd();
}

void ReadPoints3DBinary(const fs::path& path, SparseModel* model) {
  const std::string bytes = ReadFileBytes(path);
  ByteReader reader(bytes, path);
  const uint64_t count = reader.ReadCount(kMinPoint3DBytes, "3D points");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetEntry("3D point", i, count);
    Point3D point;
    point.id = reader.Read<uint64_t>();
    for (int k = 0; k < 3; ++k) point.xyz[k] = reader.ReadFinite("coordinate");
    for (int k = 0; k < 3; ++k) point.rgb[k] = reader.Read<uint8_t>();
    point.error = reader.ReadFinite("error");
    const uint64_t track_length = reader.ReadCount(kTrackElementBytes, "track elements");
    point.track.resize(track_length);
    for (TrackElement& element : point.track) {
      element.image_id = reader.Read<uint32_t>();
      element.point2d_idx = reader.Read<uint32_t>();
    }
    if (model->HasPoint3D(point.id)) reader.Fail("duplicate 3D point id " + std::to_string(point.id));
    model->AddPoint3D(std::move(point));
  }
  reader.ExpectEnd();
}

// ---------------------------------------------------------------------------------------------
// Binary writing.

namespace {

template <typename T>
void Append(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

}  // namespace

std::string CamerasBinary(const SparseModel& model) {
  std::string out;
  Append<uint64_t>(&out, model.Cameras().size());
  for (const Camera& camera : model.Cameras()) {
    Append<uint32_t>(&out, camera.id);
    Append<int32_t>(&out, static_cast<int32_t>(camera.model));
    Append<uint64_t>(&out, camera.width);
    Append<uint64_t>(&out, camera.height);
    for (const double param : camera.params) Append<double>(&out, param);
  }
  return out;
}

std::string ImagesBinary(const SparseModel& model) {
  std::string out;
  Append<uint64_t>(&out, model.Images().size());
  for (const SparseImage& image : model.Images()) {
    Append<uint32_t>(&out, image.id);
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    for (const double value : {q.w(), q.x(), q.y(), q.z()}) Append<double>(&out, value);
    for (int k = 0; k < 3; ++k) Append<double>(&out, image.cam_from_world.translation[k]);
    Append<uint32_t>(&out, image.camera_id);
    out.append(image.name);
    out.push_back('\0');
    Append<uint64_t>(&out, image.points2d.size());
    for (const Point2D& point : image.points2d) {
      Append<double>(&out, point.xy.x());
      Append<double>(&out, point.xy.y());
      Append<uint64_t>(&out, point.point3d_id);
    }
  }
  return out;
}

std::string Points3DBinary(const SparseModel& model) {
  std::string out;
  Append<uint64_t>(&out, model.Points3D().size());
  for (const Point3D& point : model.Points3D()) {
    Append<uint64_t>(&out, point.id);
    for (int k = 0; k < 3; ++k) Append<double>(&out, point.xyz[k]);
    for (int k = 0; k < 3; ++k) Append<uint8_t>(&out, point.rgb[k]);
    Append<double>(&out, point.error);
    Append<uint64_t>(&out, point.track.size());
    for (const TrackElement& element : point.track) {
      Append<uint32_t>(&out, element.image_id);
      Append<uint32_t>(&out, element.point2d_idx);
    }
  }
  return out;
}

}  // namespace parallax::sparse_formats

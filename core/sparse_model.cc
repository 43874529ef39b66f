#include "core/sparse_model.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <type_traits>

#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {
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

// Separators in text files. '\r' counts as one so that CRLF files and stray carriage returns
// read like any other blank.
constexpr std::string_view kBlank = " \t\v\f\r";

bool AllFinite(const auto& values) { return values.allFinite(); }

bool HasCamera(const SparseModel& model, uint32_t camera_id) {
  try {
    model.CameraById(camera_id);
    return true;
  } catch (const std::out_of_range&) {
    return false;
  }
}

// Whether the text format can hold `name`: the reader takes the rest of the line, trimmed.
bool IsTextSafeName(const std::string& name) {
  return !name.empty() && name.find('\n') == std::string::npos &&
         kBlank.find(name.front()) == std::string_view::npos &&
         kBlank.find(name.back()) == std::string_view::npos;
}

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
    if (!HasCamera(model, image.camera_id)) {
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

// COLMAP's "mean observations per image" and "mean track length" header values: both count
// the 2D points with a 3D point.
uint64_t NumObservations(const SparseModel& model) {
  uint64_t count = 0;
  for (const SparseImage& image : model.Images()) {
    for (const Point2D& point : image.points2d) count += point.point3d_id != kInvalidPoint3DId;
  }
  return count;
}

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

void ReadCamerasBinary(const fs::path& path, SparseModel* model) {
  const std::string bytes = ReadFileBytes(path);
  ByteReader reader(bytes, path);
  const uint64_t count = reader.ReadCount(kMinCameraBytes, "cameras");
  for (uint64_t i = 0; i < count; ++i) {
    reader.SetEntry("camera", i, count);
    Camera camera;
    camera.id = reader.Read<uint32_t>();
    const int32_t model_id = reader.Read<int32_t>();
    try {
      camera.model = CameraModelFromId(model_id);
    } catch (const std::invalid_argument&) {
      reader.Fail("unknown camera model id " + std::to_string(model_id));
    }
    camera.width = reader.Read<uint64_t>();
    camera.height = reader.Read<uint64_t>();
    camera.params.resize(NumCameraParams(camera.model));
    for (double& param : camera.params) param = reader.Read<double>();
    try {
      camera.Check();
      model->AddCamera(std::move(camera));
    } catch (const std::invalid_argument& error) {
      reader.Fail(error.what());
    }
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
    if (!HasCamera(*model, image.camera_id)) {
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
    try {
      model->AddImage(std::move(image));
    } catch (const std::invalid_argument& error) {
      reader.Fail(error.what());
    }
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
    try {
      model->AddPoint3D(std::move(point));
    } catch (const std::invalid_argument& error) {
      reader.Fail(error.what());
    }
  }
  reader.ExpectEnd();
}

// ---------------------------------------------------------------------------------------------
// Text reading.

// Lines of a whole file in memory, numbered from 1. A CRLF line keeps its '\r', a blank.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    *line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  // Skips blank and '#' lines, which COLMAP allows between entries (not inside an image).
  bool NextEntry(std::string_view* line) {
    while (Next(line)) {
      const size_t first = line->find_first_not_of(kBlank);
      if (first != std::string_view::npos && (*line)[first] != '#') return true;
    }
    return false;
  }
  size_t Number() const { return number_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  size_t number_ = 0;
};

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t pos = 0;
  while ((pos = line.find_first_not_of(kBlank, pos)) != std::string_view::npos) {
    const size_t end = std::min(line.find_first_of(kBlank, pos), line.size());
    fields.push_back(line.substr(pos, end - pos));
    pos = end;
  }
  return fields;
}

// Where in a text file we are, for messages like "cameras.txt line 4: ...".
struct TextLocation {
  const std::string& file;
  size_t line;

  [[noreturn]] void Fail(const std::string& what) const {
    throw BadInputError(file + " line " + std::to_string(line) + ": " + what);
  }
};

template <typename T>
T ParseInteger(std::string_view field, const char* name, const TextLocation& at) {
  T value{};
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (error != std::errc() || end != field.data() + field.size()) {
    at.Fail("invalid " + std::string(name) + " '" + std::string(field) + "'");
  }
  return value;
}

double ParseFinite(std::string_view field, const char* name, const TextLocation& at) {
  // from_chars is exact and locale-independent but, unlike COLMAP's std::stold, refuses '+'.
  std::string_view digits = field;
  if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-') digits.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc() || end != digits.data() + digits.size()) {
    at.Fail("invalid " + std::string(name) + " '" + std::string(field) + "'");
  }
  if (!std::isfinite(value)) {
    at.Fail("non-finite " + std::string(name) + " '" + std::string(field) + "'");
  }
  return value;
}

void ReadCamerasText(const fs::path& path, SparseModel* model) {
  const std::string text = ReadFileBytes(path), file = path.string();
  LineReader lines(text);
  std::string_view line;
  while (lines.NextEntry(&line)) {
    const TextLocation at{file, lines.Number()};
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.size() < 4) {
      at.Fail("expected CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[], got " +
              std::to_string(fields.size()) + " fields");
    }
    Camera camera;
    camera.id = ParseInteger<uint32_t>(fields[0], "CAMERA_ID", at);
    try {
      camera.model = CameraModelFromName(fields[1]);
    } catch (const std::invalid_argument&) {
      at.Fail("unknown camera model '" + std::string(fields[1]) + "'");
    }
    camera.width = ParseInteger<uint64_t>(fields[2], "WIDTH", at);
    camera.height = ParseInteger<uint64_t>(fields[3], "HEIGHT", at);
    const size_t expected = NumCameraParams(camera.model);
    if (fields.size() - 4 != expected) {
      at.Fail("expected " + std::to_string(expected) + " parameters for " +
              std::string(CameraModelName(camera.model)) + ", got " +
              std::to_string(fields.size() - 4));
    }
    for (size_t i = 4; i < fields.size(); ++i) {
      camera.params.push_back(ParseFinite(fields[i], "parameter", at));
    }
    try {
      camera.Check();
      model->AddCamera(std::move(camera));
    } catch (const std::invalid_argument& error) {
      at.Fail(error.what());
    }
  }
}

void ReadImagesText(const fs::path& path, SparseModel* model) {
  const std::string text = ReadFileBytes(path), file = path.string();
  LineReader lines(text);
  std::string_view line;
  while (lines.NextEntry(&line)) {
    const TextLocation at{file, lines.Number()};
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.size() < 10) {
      at.Fail("expected IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME, got " +
              std::to_string(fields.size()) + " fields");
    }
    SparseImage image;
    image.id = ParseInteger<uint32_t>(fields[0], "IMAGE_ID", at);
    // Members set directly, without renormalising, so values round trip exactly.
    image.cam_from_world.rotation =
        Eigen::Quaterniond(ParseFinite(fields[1], "QW", at), ParseFinite(fields[2], "QX", at),
                           ParseFinite(fields[3], "QY", at), ParseFinite(fields[4], "QZ", at));
    if (image.cam_from_world.rotation.squaredNorm() == 0) at.Fail("zero quaternion");
    image.cam_from_world.translation = Eigen::Vector3d(
        ParseFinite(fields[5], "TX", at), ParseFinite(fields[6], "TY", at),
        ParseFinite(fields[7], "TZ", at));
    image.camera_id = ParseInteger<uint32_t>(fields[8], "CAMERA_ID", at);
    if (!HasCamera(*model, image.camera_id)) {
      at.Fail("camera id " + std::to_string(image.camera_id) + " is not in cameras.txt");
    }
    // The name is the rest of the line, so names with inner spaces survive a round trip
    // (COLMAP itself would cut them at the first space).
    const size_t name_start = static_cast<size_t>(fields[9].data() - line.data());
    const size_t name_end = line.find_last_not_of(kBlank);
    image.name = std::string(line.substr(name_start, name_end + 1 - name_start));

    // The second line holds the 2D points and may be empty, so it is taken as it comes; a
    // missing one at the end of the file means no points.
    std::string_view points_line;
    if (lines.Next(&points_line)) {
      const TextLocation points_at{file, lines.Number()};
      const std::vector<std::string_view> values = SplitFields(points_line);
      if (values.size() % 3 != 0) {
        points_at.Fail("expected POINTS2D[] as (X, Y, POINT3D_ID) triples, got " +
                       std::to_string(values.size()) + " values");
      }
      image.points2d.resize(values.size() / 3);
      for (size_t i = 0; i < image.points2d.size(); ++i) {
        Point2D& point = image.points2d[i];
        point.xy.x() = ParseFinite(values[3 * i], "X", points_at);
        point.xy.y() = ParseFinite(values[3 * i + 1], "Y", points_at);
        const std::string_view id = values[3 * i + 2];
        point.point3d_id =
            id == "-1" ? kInvalidPoint3DId : ParseInteger<uint64_t>(id, "POINT3D_ID", points_at);
      }
    }
    try {
      model->AddImage(std::move(image));
    } catch (const std::invalid_argument& error) {
      at.Fail(error.what());
    }
  }
}

void ReadPoints3DText(const fs::path& path, SparseModel* model) {
  const std::string text = ReadFileBytes(path), file = path.string();
  LineReader lines(text);
  std::string_view line;
  while (lines.NextEntry(&line)) {
    const TextLocation at{file, lines.Number()};
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.size() < 8 || (fields.size() - 8) % 2 != 0) {
      at.Fail("expected POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, "
              "POINT2D_IDX) pairs, got " + std::to_string(fields.size()) + " fields");
    }
    Point3D point;
    point.id = ParseInteger<uint64_t>(fields[0], "POINT3D_ID", at);
    for (int k = 0; k < 3; ++k) point.xyz[k] = ParseFinite(fields[1 + k], "coordinate", at);
    for (int k = 0; k < 3; ++k) point.rgb[k] = ParseInteger<uint8_t>(fields[4 + k], "color", at);
    point.error = ParseFinite(fields[7], "ERROR", at);
    point.track.resize((fields.size() - 8) / 2);
    for (size_t i = 0; i < point.track.size(); ++i) {
      point.track[i].image_id = ParseInteger<uint32_t>(fields[8 + 2 * i], "IMAGE_ID", at);
      point.track[i].point2d_idx = ParseInteger<uint32_t>(fields[9 + 2 * i], "POINT2D_IDX", at);
    }
    try {
      model->AddPoint3D(std::move(point));
    } catch (const std::invalid_argument& error) {
      at.Fail(error.what());
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Writing.

template <typename T>
void Append(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

// As COLMAP's streams with precision(17): printf's "%.17g", which round trips every double.
void AppendNumber(std::string* out, double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value,
                                    std::chars_format::general, 17);
  out->append(text, result.ptr);
}

void AppendNumber(std::string* out, uint64_t value) {
  char text[24];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  out->append(text, result.ptr);
}

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

// The text writers reproduce COLMAP 3.8's output byte for byte (given the same entry order),
// header lines and separators included.
std::string CamerasText(const SparseModel& model) {
  std::string out =
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: ";
  AppendNumber(&out, uint64_t{model.Cameras().size()});
  out += '\n';
  for (const Camera& camera : model.Cameras()) {
    AppendNumber(&out, uint64_t{camera.id});
    out.append(" ").append(CameraModelName(camera.model)).append(" ");
    AppendNumber(&out, camera.width);
    out += ' ';
    AppendNumber(&out, camera.height);
    for (const double param : camera.params) out += ' ', AppendNumber(&out, param);
    out += '\n';
  }
  return out;
}

std::string ImagesText(const SparseModel& model) {
  const size_t num_images = model.Images().size();
  std::string out =
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      "# Number of images: ";
  AppendNumber(&out, uint64_t{num_images});
  out += ", mean observations per image: ";
  AppendNumber(&out, num_images == 0 ? 0.0
                                     : static_cast<double>(NumObservations(model)) /
                                           static_cast<double>(num_images));
  out += '\n';
  for (const SparseImage& image : model.Images()) {
    AppendNumber(&out, uint64_t{image.id});
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    for (const double value : {q.w(), q.x(), q.y(), q.z()}) out += ' ', AppendNumber(&out, value);
    for (int k = 0; k < 3; ++k) out += ' ', AppendNumber(&out, image.cam_from_world.translation[k]);
    out += ' ';
    AppendNumber(&out, uint64_t{image.camera_id});
    out.append(" ").append(image.name).append("\n");
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      const Point2D& point = image.points2d[i];
      if (i > 0) out += ' ';
      AppendNumber(&out, point.xy.x());
      out += ' ';
      AppendNumber(&out, point.xy.y());
      out += ' ';
      if (point.point3d_id == kInvalidPoint3DId) {
        out += "-1";
      } else {
        AppendNumber(&out, point.point3d_id);
      }
    }
    out += '\n';
  }
  return out;
}

std::string Points3DText(const SparseModel& model) {
  const size_t num_points = model.Points3D().size();
  std::string out =
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      "# Number of points: ";
  AppendNumber(&out, uint64_t{num_points});
  out += ", mean track length: ";
  AppendNumber(&out, num_points == 0 ? 0.0
                                     : static_cast<double>(NumObservations(model)) /
                                           static_cast<double>(num_points));
  out += '\n';
  for (const Point3D& point : model.Points3D()) {
    AppendNumber(&out, point.id);
    for (int k = 0; k < 3; ++k) out += ' ', AppendNumber(&out, point.xyz[k]);
    for (int k = 0; k < 3; ++k) out += ' ', AppendNumber(&out, uint64_t{point.rgb[k]});
    out += ' ';
    AppendNumber(&out, point.error);
    // COLMAP ends "ERROR " with a space and trims only the track's, so an empty track leaves
    // a trailing space; kept for byte-equal output.
    out += ' ';
    for (size_t i = 0; i < point.track.size(); ++i) {
      if (i > 0) out += ' ';
      AppendNumber(&out, uint64_t{point.track[i].image_id});
      out += ' ';
      AppendNumber(&out, uint64_t{point.track[i].point2d_idx});
    }
    out += '\n';
  }
  return out;
}

// Refuses (std::invalid_argument) what the readers would refuse, so a written model can
// always be read back.
void CheckWritable(const SparseModel& model, SparseFormat format) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("cannot write sparse model: " + what);
  };
  for (const Camera& camera : model.Cameras()) {
    try {
      camera.Check();
    } catch (const std::invalid_argument& error) {
      fail("camera " + std::to_string(camera.id) + ": " + error.what());
    }
  }
  for (const SparseImage& image : model.Images()) {
    const std::string where = "image " + std::to_string(image.id) + " ";
    const Rigid3d& pose = image.cam_from_world;
    if (!AllFinite(pose.rotation.coeffs()) || pose.rotation.squaredNorm() == 0 ||
        !AllFinite(pose.translation)) {
      fail(where + "has a non-finite or zero pose");
    }
    const bool name_fits = format == SparseFormat::kText
                               ? IsTextSafeName(image.name)
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
    throw std::invalid_argument("duplicate camera id " + std::to_string(camera.id));
  }
  cameras_.push_back(std::move(camera));
}

void SparseModel::AddImage(SparseImage image) {
  if (!image_index_.emplace(image.id, images_.size()).second) {
    throw std::invalid_argument("duplicate image id " + std::to_string(image.id));
  }
  images_.push_back(std::move(image));
}

void SparseModel::AddPoint3D(Point3D point) {
  if (!point3d_index_.emplace(point.id, points3d_.size()).second) {
    throw std::invalid_argument("duplicate 3D point id " + std::to_string(point.id));
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
    ReadCamerasBinary(dir / "cameras.bin", &model);
    ReadImagesBinary(dir / "images.bin", &model);
    ReadPoints3DBinary(dir / "points3D.bin", &model);
  } else {
    ReadCamerasText(dir / "cameras.txt", &model);
    ReadImagesText(dir / "images.txt", &model);
    ReadPoints3DText(dir / "points3D.txt", &model);
  }
  if (const auto broken = FindBrokenReference(model)) {
    throw BadInputError((dir / ("images" + extension)).string() + " and points3D" + extension +
                        " disagree: " + *broken);
  }
  return model;
}

void WriteSparseModel(const SparseModel& model, const fs::path& dir, SparseFormat format) {
  CheckWritable(model, format);
  if (format == SparseFormat::kBinary) {
    WriteFileAtomically(dir / "cameras.bin", CamerasBinary(model));
    WriteFileAtomically(dir / "images.bin", ImagesBinary(model));
    WriteFileAtomically(dir / "points3D.bin", Points3DBinary(model));
  } else {
    WriteFileAtomically(dir / "cameras.txt", CamerasText(model));
    WriteFileAtomically(dir / "images.txt", ImagesText(model));
    WriteFileAtomically(dir / "points3D.txt", Points3DText(model));
  }
}

}  // namespace parallax

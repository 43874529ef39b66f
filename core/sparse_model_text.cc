// COLMAP's text sparse-model format: cameras.txt, images.txt, points3D.txt.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/sparse_model_formats.h"

namespace parallax::sparse_formats {
namespace fs = std::filesystem;

namespace {

// Separators in text files. '\r' counts as one so that CRLF files and stray carriage returns
// read like any other blank.
constexpr std::string_view kBlank = " \t\v\f\r";

}  // namespace

// Whether the text format can hold `name`: the reader takes the rest of the line, trimmed.
bool IsTextSafeName(const std::string& name) {
  return !name.empty() && name.find('\n') == std::string::npos &&
         kBlank.find(name.front()) == std::string_view::npos &&
         kBlank.find(name.back()) == std::string_view::npos;
}

// ---------------------------------------------------------------------------------------------
// Text reading.

namespace {

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

}  // namespace

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
    const std::optional<CameraModel> camera_model = CameraModelNamed(fields[1]);
    if (!camera_model) at.Fail("unknown camera model '" + std::string(fields[1]) + "'");
    camera.model = *camera_model;
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
    if (std::string problem = camera.Problem(); !problem.empty()) at.Fail(problem);
    if (model->HasCamera(camera.id)) at.Fail("duplicate camera id " + std::to_string(camera.id));
    model->AddCamera(std::move(camera));
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
    if (!model->HasCamera(image.camera_id)) {
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
    if (model->HasImage(image.id)) at.Fail("duplicate image id " + std::to_string(image.id));
    model->AddImage(std::move(image));
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
    if (model->HasPoint3D(point.id)) at.Fail("duplicate 3D point id " + std::to_string(point.id));
    model->AddPoint3D(std::move(point));
  }
}

// ---------------------------------------------------------------------------------------------
// Text writing.

namespace {

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

}  // namespace

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

}  // namespace parallax::sparse_formats

#include "core/sparse_model.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <iomanip>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/core/sparse_model_example.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;
using sparse_model_example::kBigPointId;
using sparse_model_example::MakeCamera;
using sparse_model_example::MakeImage;
using sparse_model_example::MakeModel;
using sparse_model_example::WriteFile;
using sparse_model_example::WriteTextModel;

void ExpectSameBits(double a, double b, const std::string& what) {
  EXPECT_EQ(std::bit_cast<uint64_t>(a), std::bit_cast<uint64_t>(b))
      << what << ": " << std::setprecision(17) << a << " vs " << b;
}

void ExpectSameCamera(const Camera& a, const Camera& b) {
  const std::string what = "camera " + std::to_string(a.id);
  EXPECT_EQ(a.id, b.id) << what;
  EXPECT_EQ(a.model, b.model) << what;
  EXPECT_EQ(a.width, b.width) << what;
  EXPECT_EQ(a.height, b.height) << what;
  ASSERT_EQ(a.params.size(), b.params.size()) << what;
  for (size_t i = 0; i < a.params.size(); ++i) ExpectSameBits(a.params[i], b.params[i], what);
}

void ExpectSameImage(const SparseImage& a, const SparseImage& b) {
  const std::string what = "image " + std::to_string(a.id);
  EXPECT_EQ(a.id, b.id) << what;
  EXPECT_EQ(a.camera_id, b.camera_id) << what;
  EXPECT_EQ(a.name, b.name) << what;
  for (int k = 0; k < 4; ++k) {
    ExpectSameBits(a.cam_from_world.rotation.coeffs()[k], b.cam_from_world.rotation.coeffs()[k],
                   what + " rotation");
  }
  for (int k = 0; k < 3; ++k) {
    ExpectSameBits(a.cam_from_world.translation[k], b.cam_from_world.translation[k],
                   what + " translation");
  }
  ASSERT_EQ(a.points2d.size(), b.points2d.size()) << what;
  for (size_t i = 0; i < a.points2d.size(); ++i) {
    ExpectSameBits(a.points2d[i].xy.x(), b.points2d[i].xy.x(), what + " x");
    ExpectSameBits(a.points2d[i].xy.y(), b.points2d[i].xy.y(), what + " y");
    EXPECT_EQ(a.points2d[i].point3d_id, b.points2d[i].point3d_id) << what << " point " << i;
  }
}

void ExpectSamePoint(const Point3D& a, const Point3D& b) {
  const std::string what = "3D point " + std::to_string(a.id);
  EXPECT_EQ(a.id, b.id) << what;
  for (int k = 0; k < 3; ++k) ExpectSameBits(a.xyz[k], b.xyz[k], what + " xyz");
  EXPECT_EQ(a.rgb, b.rgb) << what;
  ExpectSameBits(a.error, b.error, what + " error");
  ASSERT_EQ(a.track.size(), b.track.size()) << what;
  for (size_t i = 0; i < a.track.size(); ++i) {
    EXPECT_EQ(a.track[i].image_id, b.track[i].image_id) << what << " track " << i;
    EXPECT_EQ(a.track[i].point2d_idx, b.track[i].point2d_idx) << what << " track " << i;
  }
}

// The same entries in the same order, every double bit for bit.
void ExpectSameModel(const SparseModel& a, const SparseModel& b) {
  ASSERT_EQ(a.Cameras().size(), b.Cameras().size());
  ASSERT_EQ(a.Images().size(), b.Images().size());
  ASSERT_EQ(a.Points3D().size(), b.Points3D().size());
  for (size_t i = 0; i < a.Cameras().size(); ++i) ExpectSameCamera(a.Cameras()[i], b.Cameras()[i]);
  for (size_t i = 0; i < a.Images().size(); ++i) ExpectSameImage(a.Images()[i], b.Images()[i]);
  for (size_t i = 0; i < a.Points3D().size(); ++i) {
    ExpectSamePoint(a.Points3D()[i], b.Points3D()[i]);
  }
}

// The same entries looked up by id: COLMAP keeps them in hash maps and writes them in its own
// order.
void ExpectSameModelIgnoringOrder(const SparseModel& expected, const SparseModel& actual) {
  ASSERT_EQ(expected.Cameras().size(), actual.Cameras().size());
  ASSERT_EQ(expected.Images().size(), actual.Images().size());
  ASSERT_EQ(expected.Points3D().size(), actual.Points3D().size());
  for (const Camera& camera : expected.Cameras()) {
    ExpectSameCamera(camera, actual.CameraById(camera.id));
  }
  for (const SparseImage& image : expected.Images()) {
    ExpectSameImage(image, actual.ImageById(image.id));
  }
  for (const Point3D& point : expected.Points3D()) {
    ExpectSamePoint(point, actual.Point3DById(point.id));
  }
}

void ExpectSameBytes(const fs::path& expected, const fs::path& actual) {
  const std::string a = ReadFileBytes(expected), b = ReadFileBytes(actual);
  const size_t common = std::min(a.size(), b.size());
  const auto difference = std::mismatch(a.begin(), a.begin() + common, b.begin()).first;
  const size_t first_difference = static_cast<size_t>(difference - a.begin());
  EXPECT_TRUE(a == b) << expected << " (" << a.size() << " bytes) and " << actual << " ("
                      << b.size() << " bytes) first differ at byte " << first_difference;
}

void ExpectSameModelFiles(const TempDir& dir, const std::string& a, const std::string& b,
                          const std::string& extension) {
  for (const char* stem : {"cameras", "images", "points3D"}) {
    ExpectSameBytes(dir.Path() / a / (stem + extension), dir.Path() / b / (stem + extension));
  }
}

bool HaveColmap() { return std::system("command -v colmap > /dev/null 2>&1") == 0; }

// Runs `colmap model_converter`; returns an empty string on success, else what went wrong.
std::string ColmapConvert(const TempDir& dir, const std::string& input, const std::string& output,
                          const std::string& output_type) {
  fs::create_directories(dir.Path() / output);
  const fs::path log = dir.Path() / (output + ".log");
  const std::string command =
      "QT_QPA_PLATFORM=offscreen colmap model_converter --input_path '" + (dir.Path() / input).string() +
      "' --output_path '" + (dir.Path() / output).string() + "' --output_type " + output_type + " > '" +
      log.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  if (status == 0) return "";
  return "`" + command + "` failed with status " + std::to_string(status) + ":\n" +
         ReadFileBytes(log);
}


TEST(SparseModel, TextRoundTripIsValueExact) {
  const TempDir dir;
  SparseModel model = MakeModel();
  // Not unit length: values are kept as read, never renormalised.
  model.MutableImages()[0].cam_from_world.rotation =
      Eigen::Quaterniond(0.1234567890123456789, 0.2 / 3, -0.3 / 7, 0.987654321);
  WriteSparseModel(model, dir.Path() / "a", SparseFormat::kText);
  const SparseModel read = ReadSparseModel(dir.Path() / "a", SparseFormat::kText);
  ExpectSameModel(model, read);

  WriteSparseModel(read, dir.Path() / "b", SparseFormat::kText);
  ExpectSameModelFiles(dir, "a", "b", ".txt");
}

TEST(SparseModel, BinaryRoundTripIsByteExact) {
  const TempDir dir;
  SparseModel model = MakeModel();
  model.MutableImages()[0].cam_from_world.rotation =
      Eigen::Quaterniond(0.1234567890123456789, 0.2 / 3, -0.3 / 7, 0.987654321);
  WriteSparseModel(model, dir.Path() / "a", SparseFormat::kBinary);
  const SparseModel read = ReadSparseModel(dir.Path() / "a", SparseFormat::kBinary);
  ExpectSameModel(model, read);

  WriteSparseModel(read, dir.Path() / "b", SparseFormat::kBinary);
  ExpectSameModelFiles(dir, "a", "b", ".bin");
}

TEST(SparseModel, WithoutKeypointsKeepsCamerasPosesAndTracks) {
  const TempDir dir;
  const SparseModel model = MakeModel();
  WriteSparseModel(model, dir.Path() / "model", SparseFormat::kBinary);
  const SparseModel read = ReadSparseModelWithoutKeypoints(dir.Path() / "model");
  ASSERT_EQ(read.Images().size(), model.Images().size());
  ASSERT_GT(model.Images()[0].points2d.size(), 0u);
  for (size_t i = 0; i < model.Images().size(); ++i) {
    EXPECT_TRUE(read.Images()[i].points2d.empty());
    EXPECT_EQ(read.Images()[i].name, model.Images()[i].name);
    EXPECT_EQ(read.Images()[i].cam_from_world.translation, model.Images()[i].cam_from_world.translation);
  }
  EXPECT_EQ(read.Cameras().size(), model.Cameras().size());
  ASSERT_EQ(read.Points3D().size(), model.Points3D().size());
  for (size_t p = 0; p < model.Points3D().size(); ++p) {
    EXPECT_EQ(read.Points3D()[p].xyz, model.Points3D()[p].xyz);
    EXPECT_EQ(read.Points3D()[p].track.size(), model.Points3D()[p].track.size());
  }
}

TEST(SparseModel, SelectImagesKeepsTheirCamerasAndThePointsTwoOfThemSee) {
  const SparseModel model = MakeModel();
  const SparseModel without_d = SelectImages(model, {"d.jpg"}, false);
  std::vector<std::string> names;
  for (const SparseImage& image : without_d.Images()) names.push_back(image.name);
  EXPECT_EQ(names, std::vector<std::string>({"dir/b.png", "a.jpg", "c.jpg"}));
  EXPECT_EQ(without_d.Cameras().size(), 3u);
  // Point 1 loses d.jpg's observation; kBigPointId, seen by b.png alone, and 10, by d.jpg, go.
  std::vector<uint64_t> ids;
  for (const Point3D& point : without_d.Points3D()) ids.push_back(point.id);
  EXPECT_EQ(ids, std::vector<uint64_t>({4, 1}));
  EXPECT_EQ(without_d.Point3DById(1).track.size(), 2u);
  EXPECT_EQ(without_d.ImageById(2).points2d.size(), 4u);
  EXPECT_EQ(without_d.ImageById(2).points2d[3].point3d_id, kInvalidPoint3DId);
  EXPECT_EQ(without_d.ImageById(2).points2d[0].point3d_id, 4u);

  const SparseModel c_and_d = SelectImages(model, {"c.jpg", "d.jpg"}, true);
  EXPECT_EQ(c_and_d.Images().size(), 2u);
  EXPECT_EQ(c_and_d.Cameras().size(), 2u);  // 7 and 1.
  EXPECT_TRUE(c_and_d.Points3D().empty());
  for (const Point2D& point : c_and_d.ImageById(9).points2d) EXPECT_EQ(point.point3d_id, kInvalidPoint3DId);
}

TEST(SparseModel, DetectsTheFormatFromTheFilesPresent) {
  const TempDir dir;
  EXPECT_EQ(DetectSparseFormat(dir.Path() / "model"), std::nullopt);
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kText);
  EXPECT_EQ(DetectSparseFormat(dir.Path() / "model"), SparseFormat::kText);
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kBinary);
  EXPECT_EQ(DetectSparseFormat(dir.Path() / "model"), SparseFormat::kBinary);
  ExpectSameModel(MakeModel(), ReadSparseModel(dir.Path() / "model"));

  fs::remove(dir.Path() / "model" / "points3D.bin");
  fs::remove(dir.Path() / "model" / "points3D.txt");
  EXPECT_EQ(DetectSparseFormat(dir.Path() / "model"), std::nullopt);
  EXPECT_THROW(ReadSparseModel(dir.Path() / "model"), BadInputError);
}

TEST(SparseModel, ColmapReadsOurBinaryAsTheSameModel) {
  ASSERT_TRUE(HaveColmap()) << "colmap is not on PATH: run scripts/install-deps";
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "ours", SparseFormat::kBinary);
  ASSERT_EQ(ColmapConvert(dir, "ours", "colmap", "TXT"), "");
  ExpectSameModelIgnoringOrder(MakeModel(), ReadSparseModel(dir.Path() / "colmap", SparseFormat::kText));
}

TEST(SparseModel, ColmapReadsOurTextAsTheSameModel) {
  ASSERT_TRUE(HaveColmap()) << "colmap is not on PATH: run scripts/install-deps";
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "ours", SparseFormat::kText);
  ASSERT_EQ(ColmapConvert(dir, "ours", "colmap", "BIN"), "");
  ExpectSameModelIgnoringOrder(MakeModel(),
                               ReadSparseModel(dir.Path() / "colmap", SparseFormat::kBinary));
}

TEST(SparseModel, RewritingColmapBinaryReproducesItsBytes) {
  ASSERT_TRUE(HaveColmap()) << "colmap is not on PATH: run scripts/install-deps";
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "ours", SparseFormat::kText);
  ASSERT_EQ(ColmapConvert(dir, "ours", "colmap", "BIN"), "");
  WriteSparseModel(ReadSparseModel(dir.Path() / "colmap", SparseFormat::kBinary), dir.Path() / "rewritten",
                   SparseFormat::kBinary);
  ExpectSameModelFiles(dir, "colmap", "rewritten", ".bin");
}

// Our text is COLMAP's, header lines and "# Number of ..." statistics included.
TEST(SparseModel, RewritingColmapTextReproducesItsBytes) {
  ASSERT_TRUE(HaveColmap()) << "colmap is not on PATH: run scripts/install-deps";
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "ours", SparseFormat::kBinary);
  ASSERT_EQ(ColmapConvert(dir, "ours", "colmap", "TXT"), "");
  WriteSparseModel(ReadSparseModel(dir.Path() / "colmap", SparseFormat::kText), dir.Path() / "rewritten",
                   SparseFormat::kText);
  ExpectSameModelFiles(dir, "colmap", "rewritten", ".txt");
}

TEST(SparseModel, ReadsTextWithCommentsBlankLinesAndCrlf) {
  const TempDir dir;
  const fs::path model = WriteTextModel(
      dir, "# cameras\r\n\r\n1 PINHOLE 4 3 2 2 2 1.5\r\n  \r\n# more\r\n",
      "# images\n\n1 1 0 0 0 0 0 0 1 name with spaces.jpg\n1 2 -1 3 4 -1\n\n# next\n"
      "2 1 0 0 0 1 2 3 1 b.jpg\n\n3 1 0 0 0 0 0 0 1 c.jpg");
  const SparseModel read = ReadSparseModel(model, SparseFormat::kText);
  ASSERT_EQ(read.Images().size(), 3u);
  EXPECT_EQ(read.CameraById(1).params, (std::vector<double>{2, 2, 2, 1.5}));
  EXPECT_EQ(read.ImageById(1).name, "name with spaces.jpg");
  ASSERT_EQ(read.ImageById(1).points2d.size(), 2u);
  EXPECT_EQ(read.ImageById(1).points2d[1].point3d_id, kInvalidPoint3DId);
  EXPECT_TRUE(read.ImageById(2).points2d.empty());
  EXPECT_TRUE(read.ImageById(3).points2d.empty());
  EXPECT_EQ(read.FindImageByName("b.jpg"), &read.ImageById(2));
}

}  // namespace
}  // namespace parallax

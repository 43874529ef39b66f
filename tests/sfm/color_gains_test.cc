#include "sfm/color_gains.h"

#include <cmath>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

constexpr int kSize = 200;
constexpr int kPoints = 300;

// One surface seen by every photo at the same pixels (the gains are all that differs): a
// smooth color field in linear light, between 0.05 and 0.6.
Eigen::Vector3f SurfaceColor(int x, int y) {
  return {0.3f + 0.25f * std::sin(x / 17.0f), 0.3f + 0.25f * std::cos(y / 13.0f),
          0.3f + 0.25f * std::sin((x + y) / 23.0f)};
}

// Photos of that surface taken with `gains` (exposure and white balance, as multipliers of
// the linear color), 8-bit sRGB PNGs like a camera's, and a model in which every photo sees
// the same points; photo `highlight_photo` has a specular highlight (bright, not clipped) over
// a tenth of it.
SparseModel WritePhotos(const std::filesystem::path& dir, const std::vector<Eigen::Vector3f>& gains,
                        int highlight_photo = -1) {
  SparseModel model;
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kPinhole;
  camera.width = kSize;
  camera.height = kSize;
  camera.params = {200, 200, 100, 100};
  model.AddCamera(camera);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> position(4, kSize - 4);
  std::vector<Eigen::Vector2d> points;
  for (int p = 0; p < kPoints; ++p) points.emplace_back(position(random), position(random));
  for (size_t i = 0; i < gains.size(); ++i) {
    Image photo(kSize, kSize, 3);
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const bool highlight = static_cast<int>(i) == highlight_photo && x < kSize / 10;
        const Eigen::Vector3f color = highlight ? Eigen::Vector3f::Constant(0.85f) : Eigen::Vector3f(SurfaceColor(x, y).cwiseProduct(gains[i]));
        for (int c = 0; c < 3; ++c) photo.At(x, y, c) = LinearToSrgb(std::min(1.0f, color[c]));
      }
    }
    const std::string name = "photo" + std::to_string(i) + ".png";
    WriteImage(dir / name, photo, PixelFormat::kUint8);
    SparseImage image;
    image.id = static_cast<uint32_t>(i + 1);
    image.camera_id = 1;
    image.name = name;
    for (const Eigen::Vector2d& xy : points) image.points2d.push_back({xy, image.points2d.size() + 1});
    model.AddImage(image);
  }
  for (size_t p = 0; p < points.size(); ++p) {
    Point3D point;
    point.id = p + 1;
    for (size_t i = 0; i < gains.size(); ++i) point.track.push_back({static_cast<uint32_t>(i + 1), static_cast<uint32_t>(p)});
    model.AddPoint3D(point);
  }
  return model;
}

TEST(ColorGains, ExposureAndWhiteBalanceStepsAreUndoneDespiteAHighlight) {
  const TempDir dir;
  // Photo 1 half as bright, photo 2 bluer, photo 3 1.8x brighter (its brightest colors clip).
  const std::vector<Eigen::Vector3f> taken_with = {
      {1, 1, 1}, {0.5f, 0.5f, 0.5f}, {0.9f, 1.0f, 1.4f}, {1.8f, 1.8f, 1.8f}};
  const SparseModel model = WritePhotos(dir.Path(), taken_with, 1);
  const ColorGainsEstimate estimate = EstimateColorGains(model, dir.Path());
  ASSERT_EQ(estimate.gains.by_photo.size(), 4u) << estimate.note;
  EXPECT_EQ(estimate.photos_without_gain, 0);
  // Corrected, every photo has the same color: gain x taken_with is one constant per channel.
  double log_sum = 0;
  for (int c = 0; c < 3; ++c) {
    const float reference = estimate.gains.Of("photo0.png")[static_cast<size_t>(c)] * taken_with[0][c];
    for (size_t i = 1; i < taken_with.size(); ++i) {
      const float corrected = estimate.gains.Of("photo" + std::to_string(i) + ".png")[static_cast<size_t>(c)] * taken_with[i][c];
      EXPECT_NEAR(corrected / reference, 1.0, 0.02) << "photo " << i << " channel " << c;
    }
  }
  // The common exposure is the set's typical one: the gains' geometric mean is 1.
  for (const auto& [name, gain] : estimate.gains.by_photo) log_sum += std::log(static_cast<double>(gain[1]));
  EXPECT_NEAR(log_sum / 4, 0.0, 1e-4);
}

TEST(ColorGains, APhotoWithTooFewUsablePointsKeepsGainOne) {
  const TempDir dir;
  // Photo 1 is so dark that every point falls below the usable range.
  const SparseModel model = WritePhotos(dir.Path(), {{1, 1, 1}, {0.005f, 0.005f, 0.005f}, {1, 1, 1}});
  const ColorGainsEstimate estimate = EstimateColorGains(model, dir.Path());
  EXPECT_EQ(estimate.photos_without_gain, 1);
  EXPECT_FALSE(estimate.gains.by_photo.contains("photo1.png"));
  EXPECT_EQ(estimate.gains.Of("photo1.png"), (RgbGain{1, 1, 1}));
  EXPECT_NEAR(estimate.gains.Of("photo0.png")[0], 1.0, 0.02);
}

TEST(ColorGains, FileRoundTripsAndRejectsBadGains) {
  const TempDir dir;
  ColorGains gains;
  gains.by_photo["a.jpg"] = {1.25f, 0.5f, 2};
  WriteColorGains(dir.Path() / "gains.json", gains);
  EXPECT_EQ(ReadColorGains(dir.Path() / "gains.json").Of("a.jpg"), (RgbGain{1.25f, 0.5f, 2}));
  gains.by_photo["b.jpg"] = {1, -1, 1};
  EXPECT_THROW(WriteColorGains(dir.Path() / "bad.json", gains), InternalError);
  std::ofstream(dir.Path() / "nan.json") << R"({"photos": {"a.jpg": [1, 0, 1]}})";
  EXPECT_THROW(ReadColorGains(dir.Path() / "nan.json"), BadInputError);
}

}  // namespace
}  // namespace parallax

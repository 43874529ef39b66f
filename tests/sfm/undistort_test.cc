#include "sfm/undistort.h"

#include <cmath>
#include <functional>
#include <numbers>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

Camera SimpleRadial(double k) {
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 160;
  camera.height = 120;
  camera.params = {150, 80, 60, k};
  return camera;
}

// A smooth pattern (periods of 11 and 14 pixels) in [0.1, 0.9], at pixel coordinates with
// centres at integer + 0.5.
double Pattern(double x, double y) {
  return 0.5 + 0.4 * std::sin(2 * std::numbers::pi * x / 11) * std::cos(2 * std::numbers::pi * y / 14);
}

// An 8-bit photo whose pixel (x, y) shows what `at(x + 0.5, y + 0.5)` returns.
Image Photo(const Camera& camera, const std::function<double(double, double)>& at) {
  Image photo(static_cast<int>(camera.width), static_cast<int>(camera.height), 3);
  for (int y = 0; y < photo.Height(); ++y) {
    for (int x = 0; x < photo.Width(); ++x) {
      for (int c = 0; c < 3; ++c) photo.At(x, y, c) = static_cast<float>(at(x + 0.5, y + 0.5));
    }
  }
  return photo;
}

TEST(UndistortPhoto, NoDistortionGivesThePhotoBackExactly) {
  const TempDir dir;
  const Camera camera = SimpleRadial(0);
  const Image photo = Photo(camera, Pattern);
  WriteImage(dir.Path() / "in.png", photo, PixelFormat::kUint8);
  UndistortPhoto(camera, dir.Path() / "in.png", dir.Path() / "out.png");
  const Image in = ReadImage(dir.Path() / "in.png"), out = ReadImage(dir.Path() / "out.png");
  ASSERT_EQ(out.Width(), 160);
  ASSERT_EQ(out.Height(), 120);
  EXPECT_EQ(out.Pixels(), in.Pixels());
  EXPECT_EQ(PinholeOf(camera).model, CameraModel::kPinhole);
  EXPECT_EQ(PinholeOf(camera).params, (std::vector<double>{150, 150, 80, 60}));
}

// A photo taken through barrel distortion (k = -0.05: 2.4 pixels at the corners) of a pattern
// drawn in the undistorted image: undistorting it gives the pattern back within 8-bit
// rounding and the resampling's error, away from the border it had to repeat.
TEST(UndistortPhoto, RecoversThePatternThroughBarrelDistortion) {
  const TempDir dir;
  const Camera camera = SimpleRadial(-0.05);
  const double f = 150, cx = 80, cy = 60;
  const Image distorted = Photo(camera, [&](double u, double v) {
    const std::optional<Eigen::Vector2d> n = camera.Undistort(Eigen::Vector2d((u - cx) / f, (v - cy) / f));
    return n ? Pattern(f * n->x() + cx, f * n->y() + cy) : 0.0;
  });
  WriteImage(dir.Path() / "in.png", distorted, PixelFormat::kUint8);
  UndistortPhoto(camera, dir.Path() / "in.png", dir.Path() / "out.png");
  const Image out = ReadImage(dir.Path() / "out.png");
  double error_sum = 0, worst = 0, moved = 0;
  int count = 0;
  for (int y = 4; y < 116; ++y) {
    for (int x = 4; x < 156; ++x) {
      const double error = std::abs(static_cast<double>(out.At(x, y, 0)) - Pattern(x + 0.5, y + 0.5));
      error_sum += error;
      worst = std::max(worst, error);
      moved = std::max(moved, std::abs(static_cast<double>(distorted.At(x, y, 0)) - Pattern(x + 0.5, y + 0.5)));
      ++count;
    }
  }
  EXPECT_LT(error_sum / count, 1.5 / 255);
  EXPECT_LT(worst, 6.0 / 255);
  EXPECT_GT(moved, 0.3);  // The distortion moved the pattern a lot.
}

TEST(UndistortPhoto, BadInputIsNamed) {
  const TempDir dir;
  try {
    UndistortPhoto(SimpleRadial(0.01), dir.Path() / "missing.png", dir.Path() / "out.png");
    FAIL() << "no exception";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  WriteImage(dir.Path() / "small.png", Image(10, 10, 3), PixelFormat::kUint8);
  EXPECT_THROW(UndistortPhoto(SimpleRadial(0.01), dir.Path() / "small.png", dir.Path() / "o.png"),
               BadInputError);
}

}  // namespace
}  // namespace parallax

// Photos COLMAP cannot read as they are: which ones the scan flags, and what the conversion
// writes (sfm/photo_set.h, sfm/photo_conversion.h).
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "sfm/photo_conversion.h"
#include "sfm/photo_set.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

// A 40x20 RGB gradient: no two pixels alike, so a wrong rotation or channel order shows.
OIIO::ImageBuf Gradient() {
  OIIO::ImageBuf image(OIIO::ImageSpec(40, 20, 3, OIIO::TypeDesc::UINT8));
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) {
      const float rgb[3] = {x / 39.0f, y / 19.0f, 1.0f - (x + y) / 58.0f};
      image.setpixel(x, y, rgb);
    }
  }
  return image;
}

void Write(OIIO::ImageBuf image, const fs::path& path, OIIO::TypeDesc type, int orientation = 1,
           const std::string& format = "") {
  image.specmod().attribute("Orientation", orientation);
  ASSERT_TRUE(image.write(path.string(), type, format)) << image.geterror();
}

const Photo& Find(const PhotoSet& set, const std::string& name) {
  for (const Photo& photo : set.photos) {
    if (photo.name == name) return photo;
  }
  throw std::runtime_error("no photo " + name);
}

// Largest difference from the gradient, in 8-bit steps, over every channel of `path`.
float StepsFromGradient(const fs::path& path) {
  const Image converted = ReadImage(path);
  const OIIO::ImageBuf gradient = Gradient();
  EXPECT_EQ(converted.Width(), 40);
  EXPECT_EQ(converted.Height(), 20);
  EXPECT_EQ(converted.Channels(), 3);
  float worst = 0;
  for (int y = 0; y < std::min(20, converted.Height()); ++y) {
    for (int x = 0; x < std::min(40, converted.Width()); ++x) {
      float expected[3];
      gradient.getpixel(x, y, expected);
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(converted.At(x, y, c) - expected[c]) * 255);
    }
  }
  return worst;
}

TEST(PhotoConversion, FormsColmapCannotReadAreFlaggedAndTheOthersAreNot) {
  const TempDir dir;
  const OIIO::ImageBuf gradient = Gradient();
  Write(gradient, dir.Path() / "plain.png", OIIO::TypeDesc::UINT8);
  Write(gradient, dir.Path() / "plain.jpg", OIIO::TypeDesc::UINT8);
  Write(gradient, dir.Path() / "deep.png", OIIO::TypeDesc::UINT16);
  Write(gradient, dir.Path() / "deep.tif", OIIO::TypeDesc::UINT16);
  Write(OIIO::ImageBufAlgo::flop(gradient), dir.Path() / "lying.jpg", OIIO::TypeDesc::UINT8, 1, "png");
  Write(OIIO::ImageBufAlgo::rotate270(gradient), dir.Path() / "turned.tif", OIIO::TypeDesc::UINT8, 6);
  Write(gradient, dir.Path() / "linear.exr", OIIO::TypeDesc::HALF);
  const PhotoSet set = ScanPhotos(dir.Path());
  EXPECT_EQ(Find(set, "plain.png").conversion, "");
  EXPECT_EQ(Find(set, "plain.jpg").conversion, "");
  EXPECT_EQ(Find(set, "deep.png").conversion, "uint16");
  EXPECT_EQ(Find(set, "deep.tif").conversion, "tiff, uint16");
  EXPECT_EQ(Find(set, "lying.jpg").conversion, "a png file named .jpg");
  EXPECT_EQ(Find(set, "turned.tif").conversion, "tiff, EXIF orientation 6");
  // Sizes are those of the upright photo: what COLMAP will see after the conversion.
  EXPECT_EQ(Find(set, "turned.tif").width, 40);
  EXPECT_EQ(Find(set, "turned.tif").height, 20);
  ASSERT_EQ(set.skipped.size(), 1u);
  EXPECT_EQ(set.skipped[0].name, "linear.exr");
  EXPECT_NE(set.skipped[0].reason.find("is not an image in a photo format"), std::string::npos) << set.skipped[0].reason;
  EXPECT_TRUE(set.NeedsConversion());
}

// One camera per size, EXIF camera and EXIF focal length (pipeline/sfm_policy.h CameraSharing).
TEST(PhotoSet, PhotosAreGroupedByCameraAndFocalLength) {
  const TempDir dir;
  float shade = 0;  // Sets one pixel apart in each: identical copies would be skipped.
  const auto write = [&](const std::string& name, const std::string& make, int focal_35mm) {
    OIIO::ImageBuf image = Gradient();
    shade += 0.15f;
    const float pixel[3] = {shade, shade, shade};
    image.setpixel(0, 0, pixel);
    if (!make.empty()) {
      image.specmod().attribute("Make", make);
      image.specmod().attribute("Model", "X1");
      image.specmod().attribute("Exif:FocalLengthIn35mmFilm", focal_35mm);
    }
    ASSERT_TRUE(image.write((dir.Path() / name).string())) << image.geterror();
  };
  write("a.jpg", "Canon", 28);
  write("b.jpg", "Canon", 28);
  write("c.jpg", "Nikon", 28);
  write("d.jpg", "Canon", 50);
  write("e.jpg", "", 0);
  write("f.png", "", 0);
  const PhotoSet set = ScanPhotos(dir.Path());
  ASSERT_EQ(set.photos.size(), 6u);
  EXPECT_EQ(set.photos[0].exif_camera, "Canon X1");
  ASSERT_TRUE(set.photos[3].exif_focal_px.has_value());
  EXPECT_NEAR(*set.photos[3].exif_focal_px, 50.0 / 36.0 * 40, 1e-9);
  const std::vector<std::vector<size_t>> expected = {{0, 1}, {2}, {3}, {4, 5}};
  EXPECT_EQ(set.CameraGroups(), expected);
  EXPECT_FALSE(set.SharesOneCamera());
}

TEST(PhotoConversion, WritesUprightEightBitRgbInTheFormatTheNameSays) {
  const TempDir dir;
  const OIIO::ImageBuf gradient = Gradient();
  Write(OIIO::ImageBufAlgo::rotate270(gradient), dir.Path() / "turned.tif", OIIO::TypeDesc::UINT16, 6);
  Write(gradient, dir.Path() / "lying.jpg", OIIO::TypeDesc::UINT8, 1, "png");
  WriteReadablePhoto(dir.Path() / "turned.tif", dir.Path() / "out" / "turned.tif");
  WriteReadablePhoto(dir.Path() / "lying.jpg", dir.Path() / "out" / "lying.jpg");
  EXPECT_LE(StepsFromGradient(dir.Path() / "out" / "turned.tif"), 0.5f);
  EXPECT_LE(StepsFromGradient(dir.Path() / "out" / "lying.jpg"), 4.0f);  // JPEG at quality 95.
  for (const char* name : {"turned.tif", "lying.jpg"}) {
    const auto input = OIIO::ImageInput::open((dir.Path() / "out" / name).string());
    ASSERT_TRUE(input);
    EXPECT_EQ(input->spec().format, OIIO::TypeDesc::UINT8) << name;
    EXPECT_EQ(input->spec().get_int_attribute("Orientation", 1), 1) << name;
  }
  EXPECT_EQ(std::string(OIIO::ImageInput::open((dir.Path() / "out" / "lying.jpg").string())->format_name()),
            "jpeg");
}

TEST(PhotoConversion, GreyIsReplicatedAndAlphaDropped) {
  const TempDir dir;
  OIIO::ImageBuf grey_alpha(OIIO::ImageSpec(32, 16, 2, OIIO::TypeDesc::UINT8));
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      const float value[2] = {x / 31.0f, y % 2 ? 0.0f : 1.0f};
      grey_alpha.setpixel(x, y, value);
    }
  }
  Write(grey_alpha, dir.Path() / "cutout.png", OIIO::TypeDesc::UINT8);
  WriteReadablePhoto(dir.Path() / "cutout.png", dir.Path() / "out.png");
  const Image rgb = ReadImage(dir.Path() / "out.png");
  ASSERT_EQ(rgb.Channels(), 3);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 32; ++x) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb.At(x, y, c), x / 31.0f, 0.5f / 255) << x << "," << y;
    }
  }
}

TEST(PhotoConversion, AnUnreadableSourceIsNamed) {
  const TempDir dir;
  std::ofstream(dir.Path() / "broken.png") << "not a png";
  try {
    WriteReadablePhoto(dir.Path() / "broken.png", dir.Path() / "out.png");
    FAIL() << "no error";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find("broken.png"), std::string::npos) << error.what();
  }
  EXPECT_FALSE(fs::exists(dir.Path() / "out.png"));
}

// A JPEG cut short decodes with a grey lower half and only a libjpeg warning: the scan skips it,
// naming the warning. A float TIFF with NaN and infinite pixels is kept, and the scan says how
// many there are and what the 8-bit conversion makes of them, which is what it writes.
TEST(PhotoSet, TruncatedPhotosAreSkippedAndNonFinitePixelsNamed) {
  const TempDir dir;
  const OIIO::ImageBuf gradient = Gradient();
  Write(gradient, dir.Path() / "whole.jpg", OIIO::TypeDesc::UINT8);
  const std::string jpeg = ReadFileBytes(dir.Path() / "whole.jpg");
  const size_t scan = jpeg.find("\xff\xda");  // The start of the compressed pixels.
  ASSERT_NE(scan, std::string::npos);
  std::ofstream(dir.Path() / "half.jpg", std::ios::binary)
      .write(jpeg.data(), static_cast<std::streamsize>((scan + jpeg.size()) / 2));
  OIIO::ImageBuf hostile(OIIO::ImageSpec(40, 20, 3, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::copy(hostile, gradient, OIIO::TypeDesc::FLOAT);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float nan_pixel[3] = {nan, nan, nan}, positive[3] = {inf, inf, inf}, negative[3] = {-inf, -inf, -inf};
  hostile.setpixel(1, 1, nan_pixel);
  hostile.setpixel(2, 1, nan_pixel);
  hostile.setpixel(3, 1, positive);
  hostile.setpixel(4, 1, negative);
  Write(hostile, dir.Path() / "hostile.tif", OIIO::TypeDesc::FLOAT);

  const PhotoSet set = ScanPhotos(dir.Path());
  ASSERT_EQ(set.skipped.size(), 1u);
  EXPECT_EQ(set.skipped[0].name, "half.jpg");
  EXPECT_NE(set.skipped[0].reason.find("is corrupt or truncated (JPEG error: Premature end of JPEG file"),
            std::string::npos)
      << set.skipped[0].reason;
  EXPECT_EQ(Find(set, "whole.jpg").non_finite, "");
  EXPECT_EQ(Find(set, "hostile.tif").non_finite,
            "6 NaN and 3 -Inf values converted to 0 (black), 3 +Inf values to 255 (white)");
  WriteReadablePhoto(dir.Path() / "hostile.tif", dir.Path() / "hostile.png");
  const Image converted = ReadImage(dir.Path() / "hostile.png");
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(converted.At(1, 1, c), 0.0f);
    EXPECT_EQ(converted.At(3, 1, c), 1.0f);
    EXPECT_EQ(converted.At(4, 1, c), 0.0f);
  }
}

}  // namespace
}  // namespace parallax

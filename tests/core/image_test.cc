#include "core/image.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

Image Gradient(int width, int height, int channels) {
  Image image(width, height, channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.At(x, y, c) = static_cast<float>((x + 3 * y + 17 * c) % 256) / 255.0f;
      }
    }
  }
  return image;
}

float MaxDifference(const Image& a, const Image& b) {
  float difference = 0;
  for (size_t i = 0; i < a.Pixels().size(); ++i) {
    difference = std::max(difference, std::abs(a.Pixels()[i] - b.Pixels()[i]));
  }
  return difference;
}

struct FormatCase {
  const char* extension;
  PixelFormat format;
  float tolerance;
};

TEST(Image, RoundTripsEveryFormatDepthAndChannelCount) {
  const TempDir dir;
  const FormatCase cases[] = {
      {".png", PixelFormat::kUint8, 0.5f / 255},  {".png", PixelFormat::kUint16, 0.5f / 65535},
      {".tif", PixelFormat::kUint8, 0.5f / 255},  {".tif", PixelFormat::kUint16, 0.5f / 65535},
      {".tif", PixelFormat::kFloat, 0},           {".exr", PixelFormat::kFloat, 0},
      {".exr", PixelFormat::kHalf, 1e-3f},
  };
  for (const FormatCase& format : cases) {
    for (const int channels : {1, 3, 4}) {
      SCOPED_TRACE(std::string(format.extension) + " channels " + std::to_string(channels));
      const Image image = Gradient(37, 23, channels);
      const auto path = dir.Path() / ("image" + std::to_string(channels) + format.extension);
      WriteImage(path, image, format.format);
      const Image read = ReadImage(path);
      ASSERT_EQ(read.Width(), 37);
      ASSERT_EQ(read.Height(), 23);
      ASSERT_EQ(read.Channels(), channels);
      EXPECT_LE(MaxDifference(image, read), format.tolerance);
    }
  }
}

TEST(Image, JpegRoundTripIsClose) {
  const TempDir dir;
  Image image(64, 64, 3);  // Smooth: JPEG is made for photos, not for sharp edges.
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) image.At(x, y, c) = static_cast<float>(x + y + 20 * c) / 200.0f;
    }
  }
  WriteImage(dir.Path() / "a.jpg", image, PixelFormat::kUint8);
  const Image read = ReadImage(dir.Path() / "a.jpg");
  ASSERT_EQ(read.Channels(), 3);
  EXPECT_LT(MaxDifference(image, read), 0.03f);  // Lossy, but the same picture.
}

TEST(Image, SrgbConversionInvertsAndMatchesTheStandard) {
  EXPECT_FLOAT_EQ(SrgbToLinear(0), 0);
  EXPECT_FLOAT_EQ(SrgbToLinear(1), 1);
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.21404f, 1e-5f);
  for (float v = 0; v <= 1; v += 1.0f / 255) EXPECT_NEAR(LinearToSrgb(SrgbToLinear(v)), v, 1e-6f);
  Image rgba(1, 1, 4);
  rgba.At(0, 0, 0) = 0.5f;
  rgba.At(0, 0, 3) = 0.5f;
  const Image linear = SrgbToLinear(rgba);
  EXPECT_NEAR(linear.At(0, 0, 0), 0.21404f, 1e-5f);
  EXPECT_FLOAT_EQ(linear.At(0, 0, 3), 0.5f);  // Alpha is not a color.
}

TEST(Image, ReadingCorruptOrMissingFilesNamesTheFile) {
  const TempDir dir;
  const auto text = dir.Path() / "not_an_image.jpg";
  std::ofstream(text) << "hello";
  EXPECT_THROW(
      try { ReadImage(text); } catch (const BadInputError& error) {
        EXPECT_NE(std::string(error.what()).find("not_an_image.jpg"), std::string::npos);
        throw;
      },
      BadInputError);
  EXPECT_THROW(ReadImage(dir.Path() / "missing.png"), BadInputError);

  WriteImage(dir.Path() / "full.png", Gradient(200, 200, 3), PixelFormat::kUint8);
  std::string bytes;
  {
    std::ifstream file(dir.Path() / "full.png", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(file), {});
  }
  std::ofstream(dir.Path() / "truncated.png", std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  EXPECT_THROW(ReadImage(dir.Path() / "truncated.png"), BadInputError);
}

// An EXR header is checked before OpenEXR reads it: a data window over the pixel limit, or an
// attribute larger than the file (a 164-byte input that made OpenEXR take 2 GB), is refused.
TEST(Image, ExrHeadersClaimingTooMuchAreRefusedBeforeDecoding) {
  const TempDir dir;
  const std::filesystem::path path = dir.Path() / "huge.exr";
  WriteImage(path, Image(4, 4, 1), PixelFormat::kHalf);
  std::string bytes;
  {
    std::ifstream file(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(file), {});
  }
  const std::string key("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const int32_t corner = 99999;
  for (size_t offset : {size_t{8}, size_t{12}}) std::memcpy(&bytes[at + key.size() + 4 + offset], &corner, 4);
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  try {
    ReadImage(path);
    FAIL() << "read";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find("claims 100000x100000 pixels, over the 128 MP limit"), std::string::npos)
        << error.what();
  }
  const std::filesystem::path fuzzed = SourceDir() / "fuzz" / "corpus" / "image" /
                                       "oom-9c45bac25791af1ef2c637f764c39cf9191af3c4";
  std::ifstream input(fuzzed, std::ios::binary);
  const std::string header((std::istreambuf_iterator<char>(input)), {});
  std::ofstream(dir.Path() / "fuzzed.exr", std::ios::binary).write(header.data() + 1, static_cast<std::streamsize>(header.size() - 1));
  EXPECT_THROW(ReadImage(dir.Path() / "fuzzed.exr"), BadInputError);
}

// A 6-row BMP whose header claims 16,711,688 columns (100 MP, under the pixel limit), found by
// fuzzing: OpenImageIO reads it in chunks of rows allocated for the full width, 12.8 GB. No
// side may exceed JPEG's 65535 px.
TEST(Image, ImagesWiderThanTheSideLimitAreRefusedBeforeDecoding) {
  const TempDir dir;
  const std::filesystem::path fuzzed = SourceDir() / "fuzz" / "corpus" / "image" /
                                       "oom-3326eefd5a50c4f47e7c0f902837da248dc4e289";
  std::ifstream input(fuzzed, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(input)), {});
  std::ofstream(dir.Path() / "wide.bmp", std::ios::binary).write(bytes.data() + 1, static_cast<std::streamsize>(bytes.size() - 1));
  try {
    ReadImage(dir.Path() / "wide.bmp");
    FAIL() << "read";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find("is 16711688x6, over the 65535 px side limit"), std::string::npos)
        << error.what();
  }
  EXPECT_TRUE(OverPixelLimit(65536, 16));
  EXPECT_FALSE(OverPixelLimit(65535, 1953));  // 128 MP.
  EXPECT_TRUE(OverPixelLimit(65535, 1954));
}

TEST(Image, WritingNanIsRefusedAndLeavesNoFile) {
  const TempDir dir;
  Image image(4, 4, 3);
  image.At(1, 1, 1) = std::nanf("");
  EXPECT_THROW(WriteImage(dir.Path() / "nan.exr", image, PixelFormat::kFloat),
               InternalError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.Path()));
}

TEST(Image, WritesAreAtomicAndReproducible) {
  const TempDir dir;
  const Image image = Gradient(50, 40, 3);
  WriteImage(dir.Path() / "a.exr", image, PixelFormat::kFloat);
  WriteImage(dir.Path() / "b.exr", image, PixelFormat::kFloat);
  std::ifstream a(dir.Path() / "a.exr", std::ios::binary), b(dir.Path() / "b.exr", std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}),
            std::string(std::istreambuf_iterator<char>(b), {}));
  // Only the two final files: no temporary left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.Path()),
                          std::filesystem::directory_iterator()),
            2);
}

}  // namespace
}  // namespace parallax

#include "core/depth_map.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

DepthMap MakeDepth(int width, int height) {
  DepthMap depth(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) depth.At(x, y) = (x + y) % 7 == 0 ? 0.0f : 0.5f + 0.013f * x * y;
  }
  return depth;
}

void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(DepthMap, ExrRoundTripIsExact) {
  const TempDir dir;
  const DepthMap depth = MakeDepth(31, 17);
  WriteDepthExr(dir.Path() / "d.exr", depth);
  const DepthMap read = ReadDepthExr(dir.Path() / "d.exr");
  ASSERT_EQ(read.Width(), 31);
  ASSERT_EQ(read.Height(), 17);
  EXPECT_EQ(read.Values(), depth.Values());
}

TEST(DepthMap, ExrReaderAcceptsAnySingleChannelName) {
  const TempDir dir;
  Image grey(5, 4, 1);
  grey.At(2, 3, 0) = 7.5f;
  WriteImage(dir.Path() / "y.exr", grey, PixelFormat::kFloat);  // Channel "Y".
  EXPECT_FLOAT_EQ(ReadDepthExr(dir.Path() / "y.exr").At(2, 3), 7.5f);
  WriteImage(dir.Path() / "rgb.exr", Image(5, 4, 3), PixelFormat::kFloat);
  EXPECT_THROW(ReadDepthExr(dir.Path() / "rgb.exr"), BadInputError);
}

// A map at the depth stage's working size is read at its photo's, each pixel holding the value
// of the map's pixel its centre falls in; a map larger than the photo, or of another shape, is
// an error naming the file.
TEST(DepthMap, WorkingSizeMapsAreReadAtThePhotosSizeNearest) {
  const TempDir dir;
  const DepthMap small = MakeDepth(20, 13);  // 0.667 of 30x20, as a 1024 cap makes 1536x1024.
  WriteDepthExr(dir.Path() / "d.exr", small);
  const DepthMap full = ReadDepthExrAt(dir.Path() / "d.exr", 30, 20);
  ASSERT_EQ(full.Width(), 30);
  ASSERT_EQ(full.Height(), 20);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 30; ++x) {
      // The centre (x + 0.5, y + 0.5) scaled by 20/30 and 13/20.
      const int sx = static_cast<int>((x + 0.5) * 20 / 30), sy = static_cast<int>((y + 0.5) * 13 / 20);
      ASSERT_EQ(full.At(x, y), small.At(sx, sy)) << x << "," << y;
    }
  }
  EXPECT_EQ(ReadDepthExrAt(dir.Path() / "d.exr", 20, 13).Values(), small.Values());
  for (const auto& [width, height] : {std::pair{19, 13}, std::pair{30, 30}, std::pair{20, 12}}) {
    try {
      ReadDepthExrAt(dir.Path() / "d.exr", width, height);
      ADD_FAILURE() << "a 20x13 map read at " << width << "x" << height;
    } catch (const BadInputError& error) {
      EXPECT_NE(std::string(error.what()).find("d.exr is 20x13"), std::string::npos) << error.what();
    }
  }
}

TEST(DepthMap, ColmapDenseLayoutIsChannelMajorWithAsciiHeader) {
  const TempDir dir;
  DenseArray normals{3, 2, 3, {}};
  for (int i = 0; i < 18; ++i) normals.values.push_back(static_cast<float>(i));
  WriteColmapArray(dir.Path() / "n.bin", normals);
  std::ifstream file(dir.Path() / "n.bin", std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(file), {});
  ASSERT_EQ(bytes.substr(0, 6), "3&2&3&");
  ASSERT_EQ(bytes.size(), 6 + 18 * sizeof(float));
  float value;
  // Index (c * H + row) * W + col: channel 1, row 1, col 2 -> (1 * 2 + 1) * 3 + 2 = 11.
  std::memcpy(&value, bytes.data() + 6 + 11 * sizeof(float), sizeof(float));
  EXPECT_EQ(value, 11.0f);
  const DenseArray read = ReadColmapArray(dir.Path() / "n.bin");
  EXPECT_EQ(read.values, normals.values);
  EXPECT_EQ(read.channels, 3);
}

TEST(DepthMap, ColmapDepthRoundTripIsExact) {
  const TempDir dir;
  const DepthMap depth = MakeDepth(40, 30);
  WriteColmapDepth(dir.Path() / "0000.png.geometric.bin", depth);
  EXPECT_EQ(ReadColmapDepth(dir.Path() / "0000.png.geometric.bin").Values(), depth.Values());
}

TEST(DepthMap, LyingOrMalformedDenseHeadersAreRejectedBeforeAllocating) {
  const TempDir dir;
  const std::string four_floats(16, '\0');
  const struct {
    const char* name;
    std::string bytes;
  } cases[] = {
      {"overflow.bin", "2147483647&2147483647&2147483647&" + four_floats},
      {"too_big.bin", "100&100&1&" + four_floats},
      {"too_small.bin", "1&1&1&" + four_floats},
      {"negative.bin", "-2&-2&1&" + four_floats},
      {"garbage.bin", "abc&2&1&" + four_floats},
      {"no_header.bin", four_floats},
      {"empty.bin", ""},
  };
  for (const auto& bad : cases) {
    WriteBytes(dir.Path() / bad.name, bad.bytes);
    try {
      ReadColmapArray(dir.Path() / bad.name);
      ADD_FAILURE() << bad.name << " was accepted";
    } catch (const BadInputError& error) {
      EXPECT_NE(std::string(error.what()).find(bad.name), std::string::npos) << error.what();
    }
  }
}

TEST(DepthMap, NanInfAndNegativeDepthNeverReachAFile) {
  const TempDir dir;
  for (const float bad : {std::nanf(""), std::numeric_limits<float>::infinity(), -1.0f}) {
    DepthMap depth = MakeDepth(8, 8);
    depth.At(3, 3) = bad;
    EXPECT_THROW(WriteDepthExr(dir.Path() / "d.exr", depth), InternalError);
    EXPECT_THROW(WriteColmapDepth(dir.Path() / "d.bin", depth), InternalError);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.Path()));
  // A file written elsewhere with NaN is refused on reading.
  Image nan_image(2, 2, 1);
  nan_image.At(0, 0, 0) = 1;
  WriteImage(dir.Path() / "ok.exr", nan_image, PixelFormat::kFloat);
  std::string bytes = std::string(4, '\0');
  const float nan = std::nanf("");
  std::memcpy(bytes.data(), &nan, 4);
  WriteBytes(dir.Path() / "nan.bin", "1&1&1&" + bytes);
  EXPECT_THROW(ReadColmapDepth(dir.Path() / "nan.bin"), BadInputError);
}

}  // namespace
}  // namespace parallax

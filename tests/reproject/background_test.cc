// The depth a warp starts from: which pixels are background, and the specks and edges
// cleared before warping (reproject/background.h).
#include "reproject/background.h"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "core/depth_map.h"
#include "core/error.h"

namespace parallax {
namespace {

TEST(MarkBackground, OnlyDepthZeroConnectedToTheBorderIsBackground) {
  DepthMap depth(8, 6);
  for (int y = 1; y < 5; ++y) {
    for (int x = 1; x < 7; ++x) depth.At(x, y) = 3;
  }
  depth.At(3, 2) = 0;  // Enclosed: unknown.
  depth.At(1, 3) = 0;  // Touches the border ring through (0, 3).
  const Image plain(8, 6, 3);
  const std::vector<uint8_t> background = MarkBackground(depth, plain, 0.05f);
  EXPECT_EQ(background[0], 1);
  EXPECT_EQ(background[2 * 8 + 3], 0);
  EXPECT_EQ(background[3 * 8 + 1], 1);
  EXPECT_EQ(background[2 * 8 + 2], 0);
}

// No depth along the top border: smooth sky-like color there is background, a texture is
// not, and the color test can be turned off. Below the scene (depth in rows 2-3), smooth
// color without depth reaching only the bottom border is ground, not sky.
TEST(MarkBackground, TexturedPixelsAndGroundWithoutDepthAreUnknown) {
  DepthMap depth(8, 6);
  Image color(8, 6, 3);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool textured = x >= 4 && (x + y) % 2 == 0;
      for (int c = 0; c < 3; ++c) color.At(x, y, c) = textured ? 0.2f : 0.6f + 0.001f * static_cast<float>(x);
      if (y == 2 || y == 3) depth.At(x, y) = 2;
    }
  }
  const std::vector<uint8_t> background = MarkBackground(depth, color, 0.05f);
  EXPECT_EQ(background[0 * 8 + 1], 1);  // Smooth gradient.
  EXPECT_EQ(background[0 * 8 + 5], 0);  // Checkerboard.
  EXPECT_EQ(background[0 * 8 + 6], 0);
  EXPECT_EQ(background[2 * 8 + 1], 0);  // Has depth.
  EXPECT_EQ(background[5 * 8 + 1], 0);  // Smooth, but below the scene.
  const std::vector<uint8_t> untested = MarkBackground(depth, color, 1.0f);
  EXPECT_EQ(untested[0 * 8 + 5], 1);
  EXPECT_EQ(untested[5 * 8 + 1], 0);
  EXPECT_THROW(MarkBackground(depth, Image(7, 6, 3), 0.05f), InternalError);
}

// A wall with a 5-pixel speck in front of it and a lone pixel in the sky: both cleared; the
// wall, a steep but continuous ramp, stays.
TEST(RemoveDepthSpeckles, ClearsSmallPatchesOnly) {
  DepthMap depth(40, 30);
  for (int y = 10; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) depth.At(x, y) = 5.0f * std::pow(1.05f, static_cast<float>(x));
  }
  for (int x = 10; x < 15; ++x) depth.At(x, 20) = 2;  // Speck in front of the wall.
  depth.At(20, 3) = 7;                                // Alone in the sky.
  DepthMap cleaned = depth;
  EXPECT_EQ(RemoveDepthSpeckles(&cleaned, 10, 0.1f), 6);
  EXPECT_EQ(cleaned.At(12, 20), 0);
  EXPECT_EQ(cleaned.At(20, 3), 0);
  EXPECT_EQ(cleaned.At(39, 29), depth.At(39, 29));
  EXPECT_EQ(cleaned.At(12, 21), depth.At(12, 21));
  // A 5% step per pixel is one surface at max_step 0.1, not at 0.01: there every column is
  // its own patch of 20 pixels (9 and 10 where the speck was), kept at 8, cleared at 20.
  DepthMap strict = cleaned;
  EXPECT_EQ(RemoveDepthSpeckles(&strict, 8, 0.01f), 0);
  EXPECT_EQ(RemoveDepthSpeckles(&strict, 20, 0.01f), 40 * 20 - 5);
  EXPECT_THROW(RemoveDepthSpeckles(&strict, 10, 0), InternalError);
}

// A box (depth 4) in front of a wall (depth 8), on a 20x10 map: two pixels of the box along
// its edge go, the wall and the box's inside stay; a gentle slope is no edge.
TEST(ErodeDepthEdges, ClearsTheNearSideOfEdgesOnly) {
  DepthMap depth(20, 10);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) depth.At(x, y) = x >= 5 && x < 15 ? 4.0f : 8.0f;
  }
  DepthMap eroded = depth;
  EXPECT_EQ(ErodeDepthEdges(&eroded, 0.05f, 2), 2 * 2 * 10);
  for (int y = 0; y < 10; ++y) {
    EXPECT_EQ(eroded.At(4, y), 8) << "the wall stays";
    EXPECT_EQ(eroded.At(5, y), 0);
    EXPECT_EQ(eroded.At(6, y), 0);
    EXPECT_EQ(eroded.At(7, y), 4) << "the third pixel in stays";
    EXPECT_EQ(eroded.At(14, y), 0);
    EXPECT_EQ(eroded.At(13, y), 0);
    EXPECT_EQ(eroded.At(12, y), 4);
    EXPECT_EQ(eroded.At(15, y), 8);
  }
  DepthMap untouched = depth;
  EXPECT_EQ(ErodeDepthEdges(&untouched, 0.05f, 0), 0);
  EXPECT_EQ(untouched.Values(), depth.Values());
  DepthMap slope(20, 10);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) slope.At(x, y) = 5.0f * std::pow(1.03f, static_cast<float>(x));
  }
  EXPECT_EQ(ErodeDepthEdges(&slope, 0.05f, 2), 0);
  EXPECT_THROW(ErodeDepthEdges(&slope, 0, 2), InternalError);
}

// Sky color encodes the world direction, so a warped sky pixel tells where it came from.

}  // namespace
}  // namespace parallax

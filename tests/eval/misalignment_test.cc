// Misalignment by dense optical flow: a photo shifted by a known sub-pixel offset is measured
// at that offset where the photo has texture, an exposure change moves it little, and only the
// masked pixels count.
#include "eval/misalignment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image.h"
#include "core/image_sampling.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

// A rendered courtyard photo (320 x 240): texture, edges and flat walls, as renders have.
Image Photo() { return ReadImage(SourceDir() / "example_images" / "small" / "images" / "0000.png"); }

// `image` moved by `offset` px (bilinear), times `gain`: what was at p is at p + offset.
Image Shifted(const Image& image, const Eigen::Vector2f& offset, float gain = 1) {
  Image out(image.Width(), image.Height(), 3);
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      const Eigen::Vector3f color = SampleBilinear(image, Eigen::Vector2f(x + 0.5f, y + 0.5f) - offset);
      for (int c = 0; c < 3; ++c) out.At(x, y, c) = std::min(1.0f, gain * color[c]);
    }
  }
  return out;
}

// The textured pixels at least `margin` px inside the frame with x in [x_begin, x_end).
std::vector<uint8_t> Columns(const Image& image, int x_begin, int x_end, int margin = 8) {
  std::vector<uint8_t> mask = TexturedPixels(image);
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      const bool inside = y >= margin && y < image.Height() - margin && x >= std::max(x_begin, margin) &&
                          x < std::min(x_end, image.Width() - margin);
      if (!inside) mask[static_cast<size_t>(y) * image.Width() + x] = 0;
    }
  }
  return mask;
}

// Measured: 65% of the photo; its sky and flat walls are left out.
TEST(Misalignment, FlatPixelsAreNotMeasured) {
  const Image photo = Photo();
  const std::vector<uint8_t> textured = TexturedPixels(photo);
  const double share = static_cast<double>(std::count(textured.begin(), textured.end(), uint8_t{1})) /
                       static_cast<double>(textured.size());
  EXPECT_GT(share, 0.5);
  EXPECT_LT(share, 0.8);
  Image flat(64, 48, 3);
  for (float& value : flat.Pixels()) value = 0.5f;
  const std::vector<uint8_t> none = TexturedPixels(flat);
  EXPECT_EQ(std::count(none.begin(), none.end(), uint8_t{1}), 0);
}

const Eigen::Vector2f kOffset(1.25f, -0.5f);
const double kOffsetPx = std::hypot(1.25, -0.5);  // 1.35 px.

TEST(Misalignment, AnAlignedPhotoHasNoFlow) {
  const Image photo = Photo();
  const Misalignment misalignment = MisalignmentOf(FlowLength(photo, photo), Columns(photo, 0, photo.Width()));
  EXPECT_LT(misalignment.median_px, 0.02);
  EXPECT_LT(misalignment.p90_px, 0.05);
}

TEST(Misalignment, AShiftedPhotoIsMeasuredAtItsOffset) {
  const Image render = Photo();
  const Misalignment misalignment =
      MisalignmentOf(FlowLength(render, Shifted(render, kOffset)), Columns(render, 0, render.Width()));
  std::printf("[ measure ] %.3f px shift: median %.3f px, p90 %.3f px\n", kOffsetPx, misalignment.median_px,
              misalignment.p90_px);
  // Measured 1.341 and 1.406 px.
  EXPECT_NEAR(misalignment.median_px, kOffsetPx, 0.05);
  EXPECT_NEAR(misalignment.p90_px, kOffsetPx, 0.2);
}

// DIS normalises its patches' means, not their contrast: evaluation matches the render's
// exposure to the photo first.
TEST(Misalignment, ADarkerPhotoIsMeasuredNearItsOffset) {
  const Image render = Photo();
  const Misalignment misalignment =
      MisalignmentOf(FlowLength(render, Shifted(render, kOffset, 0.7f)), Columns(render, 0, render.Width()));
  std::printf("[ measure ] %.3f px shift, 0.7 gain: median %.3f px, p90 %.3f px\n", kOffsetPx,
              misalignment.median_px, misalignment.p90_px);
  EXPECT_NEAR(misalignment.median_px, kOffsetPx, 0.15);
}

// The left half shifted, the right half not: each half's mask measures its own.
TEST(Misalignment, OnlyTheMaskedPixelsCount) {
  const Image render = Photo();
  const Image shifted = Shifted(render, kOffset);
  Image photo = render;
  const int half = render.Width() / 2;
  for (int y = 0; y < render.Height(); ++y) {
    for (int x = 0; x < half; ++x) {
      for (int c = 0; c < 3; ++c) photo.At(x, y, c) = shifted.At(x, y, c);
    }
  }
  const Image flow = FlowLength(render, photo);
  EXPECT_NEAR(MisalignmentOf(flow, Columns(render, 0, half - 16)).median_px, kOffsetPx, 0.15);
  EXPECT_LT(MisalignmentOf(flow, Columns(render, half + 16, render.Width())).median_px, 0.15);
  EXPECT_EQ(MisalignmentOf(flow, std::vector<uint8_t>(flow.Pixels().size(), 0)).p90_px, 0);
  EXPECT_THROW(MisalignmentOf(flow, {1, 0, 1}), InternalError);
  EXPECT_THROW(FlowLength(render, Image(8, 8, 3)), InternalError);
}

}  // namespace
}  // namespace parallax

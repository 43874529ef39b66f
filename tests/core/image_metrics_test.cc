#include "core/image_metrics.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

Image Pattern(int width, int height) {
  Image image(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.At(x, y, c) = static_cast<float>(0.5 + 0.3 * std::sin(0.3 * x + 0.2 * y + c));
      }
    }
  }
  return image;
}

TEST(ImageMetrics, PsnrOfAConstantOffsetIsAnalytic) {
  const Image reference = Pattern(40, 30);
  Image shifted = reference;
  for (float& value : shifted.Pixels()) value += 0.01f;
  // MSE = 1e-4 -> 40 dB.
  EXPECT_NEAR(Psnr(shifted, reference), 40.0, 1e-3);
  EXPECT_DOUBLE_EQ(Psnr(reference, reference), 100.0);
}

TEST(ImageMetrics, PsnrMaskSelectsPixels) {
  const Image reference = Pattern(10, 10);
  Image damaged = reference;
  std::vector<uint8_t> mask(100, 1);
  for (int x = 0; x < 10; ++x) {
    damaged.At(x, 0, 0) = 1.0f;  // Row 0 ruined, and masked out.
    mask[static_cast<size_t>(x)] = 0;
  }
  EXPECT_DOUBLE_EQ(Psnr(damaged, reference, mask), 100.0);
  EXPECT_LT(Psnr(damaged, reference), 30.0);
  EXPECT_EQ(Psnr(damaged, reference, std::vector<uint8_t>(100, 0)), 0.0);
}

TEST(ImageMetrics, SsimIsOneForIdenticalAndFallsWithNoise) {
  const Image reference = Pattern(48, 32);
  EXPECT_NEAR(Ssim(reference, reference), 1.0, 1e-12);
  Image noisy = reference;
  uint32_t state = 12345;
  for (float& value : noisy.Pixels()) {
    state = state * 1664525u + 1013904223u;
    value += 0.3f * (static_cast<float>(state >> 8) / 16777216.0f - 0.5f);
  }
  const double ssim = Ssim(noisy, reference);
  EXPECT_LT(ssim, 0.9);
  EXPECT_GT(ssim, 0.3);
  EXPECT_THROW(Ssim(Pattern(4, 4), reference), InternalError);
}

}  // namespace
}  // namespace parallax

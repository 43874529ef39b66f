#include "reproject/fill_from_sources.h"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/reproject/analytic_scene.h"

namespace parallax {
namespace {
using test::CameraAt;

constexpr int kWidth = 200, kHeight = 150;
constexpr float kFillDepth = 8;
const Eigen::Vector3f kFillColor(1, 0, 1);

// The source's color, affine in its pixel coordinates: bilinear sampling is exact.
Eigen::Vector3f SourceColor(double x, double y) {
  return {static_cast<float>(x / kWidth), static_cast<float>(y / kHeight), 0.3f};
}

struct Case {
  Camera camera = MakePinholeCamera(1, kWidth, kHeight, 200, 200, 100, 75);
  PosedCamera target = CameraAt(camera, {0, 0, 0});
  PosedCamera source_camera = CameraAt(camera, {0.5, 0, 0});
  Image color;
  DepthMap depth;
  std::vector<uint8_t> sky;
  BlendResult blend;
  ClassMap classes;

  // The source has no depth but in three blocks: something at depth 2 in front of the plane
  // the fill continues (at depth 8), the plane itself 2% off, and sky marked at depth 0.
  Case() {
    color.Reset(kWidth, kHeight, 3);
    depth.Reset(kWidth, kHeight);
    sky.assign(kWidth * kHeight, 0);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        for (int c = 0; c < 3; ++c) color.At(x, y, c) = SourceColor(x, y)(c);
        if (y < 30 && x < 60) depth.At(x, y) = 2;
        if (y < 30 && x >= 60 && x < 120) depth.At(x, y) = 1.02f * kFillDepth;
        if (y >= 120 && x < 60) sky[static_cast<size_t>(y * kWidth + x)] = 1;
      }
    }
    blend.color.Reset(kWidth, kHeight, 3);
    blend.depth.Reset(kWidth, kHeight);
    blend.kind.assign(kWidth * kHeight, SampleKind::kNone);
    classes = {kWidth, kHeight, std::vector<PixelClass>(kWidth * kHeight, PixelClass::kDisocclusion), {}};
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        for (int c = 0; c < 3; ++c) blend.color.At(x, y, c) = kFillColor(c);
        blend.depth.At(x, y) = kFillDepth;
        if (x >= 190) classes.classes[static_cast<size_t>(y * kWidth + x)] = PixelClass::kOutOfView;
      }
    }
  }

  // Where target pixel (x, y) at the fill's depth lands in the source.
  Eigen::Vector2d InSource(int x, int y) const {
    const Eigen::Vector3d point = kFillDepth * Eigen::Vector3d((x + 0.5 - 100) / 200, (y + 0.5 - 75) / 200, 1);
    const Eigen::Vector3d local = point - Eigen::Vector3d(0.5, 0, 0);
    return {200 * local.x() / local.z() + 100, 200 * local.y() / local.z() + 75};
  }
};

TEST(FillFromSources, HolesTakeTheColorOfTheSourceThatSawTheirSurface) {
  Case c;
  const FillSource source{c.source_camera, &c.color, &c.depth, &c.sky};
  const FillFromSourcesSummary summary =
      FillFromSources(c.classes, c.target, std::span<const FillSource>(&source, 1), &c.blend);
  int colored = 0, kept = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Eigen::Vector2d at = c.InSource(x, y);
      const double u = at.x() - 0.5, v = at.y() - 0.5;
      const bool inside = u >= 0 && v >= 0 && u < kWidth - 1 && v < kHeight - 1;
      const int nx = static_cast<int>(at.x()), ny = static_cast<int>(at.y());
      const bool seen = inside && x < 190 && !(ny < 30 && nx < 60) && !(ny >= 120 && nx < 60);
      const Eigen::Vector3f expected = seen ? SourceColor(u, v) : kFillColor;
      for (int ch = 0; ch < 3; ++ch) {
        ASSERT_NEAR(c.blend.color.At(x, y, ch), expected(ch), 1e-5) << x << "," << y;
      }
      ASSERT_EQ(c.blend.depth.At(x, y), kFillDepth);
      (seen ? colored : kept) += 1;
    }
  }
  EXPECT_EQ(summary.colored_px, colored);
  // Each case is there: the plane 2% off (taken), in front of it, sky, out of view, outside.
  EXPECT_GT(colored, kWidth * kHeight / 2);
  EXPECT_GT(kept, 40 * kHeight);
}

TEST(FillFromSources, RefusesASourceWithoutDepth) {
  Case c;
  const FillSource source{c.source_camera, &c.color, nullptr, &c.sky};
  EXPECT_THROW(FillFromSources(c.classes, c.target, std::span<const FillSource>(&source, 1), &c.blend),
               InternalError);
}

}  // namespace
}  // namespace parallax

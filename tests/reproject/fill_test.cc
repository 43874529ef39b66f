#include "reproject/fill.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/error.h"
#include "reproject/forward_warp.h"
#include "reproject/render.h"
#include "tests/reproject/analytic_scene.h"

namespace parallax {
namespace {
using test::CameraAt;

const Eigen::Vector3f kWallBlue(0.05f, 0.1f, 0.8f);
const Eigen::Vector3f kBoxRed(0.8f, 0.05f, 0.05f);

struct FillCase {
  SourceView source;
  PosedCamera target;
};

// A plain red box in front of a plain blue wall, seen from 0.5 to the right: a wide
// disocclusion to the right of the box.
FillCase RedBoxBlueWall() {
  const Camera camera = MakePinholeCamera(1, 200, 150, 200, 200, 100, 75);
  test::Scene scene;
  scene.planes.push_back(test::WallAt(8, [](const Eigen::Vector3d&) { return kWallBlue; }));
  scene.boxes.push_back({{-0.8, -0.6, 4}, {0.8, 0.6, 5}, [](const Eigen::Vector3d&) { return kBoxRed; }});
  return {test::RenderView(scene, CameraAt(camera, {0, 0, 0})), CameraAt(camera, {0.5, 0, 0})};
}

RenderResult RenderWith(const FillCase& c, FillMethod fill) {
  RenderOptions options;
  options.fill.method = fill;
  return Render({&c.source}, c.target, options);
}

TEST(FillHoles, DepthAwareFillTakesTheBackgroundColor) {
  const FillCase c = RedBoxBlueWall();
  const RenderResult result = RenderWith(c, FillMethod::kDepthAware);
  ASSERT_GT(result.metrics.disocclusion_ratio, 0.01);
  int checked = 0;
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x) {
      if (!IsHole(result.classes.At(x, y))) continue;
      ++checked;
      for (int ch = 0; ch < 3; ++ch) {
        // The wall's color within the roundings of the texture and the warp buffer (half
        // floats).
        ASSERT_NEAR(result.color.At(x, y, ch), kWallBlue(ch),
                    1e-4 + 2 * WarpBuffer::kHalfRounding * static_cast<double>(kWallBlue(ch)))
            << x << "," << y;
      }
      EXPECT_NEAR(result.depth.At(x, y), 8, 0.01);
    }
  }
  EXPECT_GT(checked, 300);
  EXPECT_EQ(result.fill.hole_ratio_filled, 0);
  EXPECT_EQ(result.fill.filled_px,
            static_cast<int>(std::lround((result.metrics.hole_ratio + result.metrics.out_of_view_ratio) * 200 * 150)));
}

TEST(FillHoles, TeleaInpaintingMixesForegroundIntoTheHole) {
  const FillCase c = RedBoxBlueWall();
  const RenderResult result = RenderWith(c, FillMethod::kInpaint);
  double red = 0;
  int count = 0;
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x) {
      if (result.classes.At(x, y) != PixelClass::kDisocclusion) continue;
      red += static_cast<double>(result.color.At(x, y, 0));
      ++count;
    }
  }
  ASSERT_GT(count, 0);
  // The wall's red is 0.05; Telea pulls in the box's 0.8 from the hole's left edge.
  EXPECT_GT(red / count, 0.1);
  EXPECT_EQ(result.fill.hole_ratio_filled, 0);
}

TEST(FillHoles, NoFillLeavesHolesBlackAndCountsThem) {
  const FillCase c = RedBoxBlueWall();
  const RenderResult result = RenderWith(c, FillMethod::kNone);
  EXPECT_NEAR(result.fill.hole_ratio_filled,
              result.metrics.hole_ratio + result.metrics.out_of_view_ratio, 1e-12);
  for (int y = 0; y < 150; ++y) {
    for (int x = 0; x < 200; ++x) {
      if (IsHole(result.classes.At(x, y))) {
        ASSERT_EQ(result.color.At(x, y, 2), 0);
      }
    }
  }
}

TEST(FillHoles, OutOfViewIsLeftWhenAsked) {
  const FillCase c = RedBoxBlueWall();
  RenderOptions options;
  options.fill.fill_out_of_view = false;
  const RenderResult result = Render({&c.source}, c.target, options);
  EXPECT_GT(result.metrics.out_of_view_ratio, 0.01);
  EXPECT_NEAR(result.fill.hole_ratio_filled, result.metrics.out_of_view_ratio, 1e-12);
}

// A width x height blend where nothing landed.
BlendResult EmptyBlend(int width, int height) {
  BlendResult blend;
  blend.color.Reset(width, height, 3);
  blend.depth.Reset(width, height);
  blend.kind.assign(static_cast<size_t>(width) * static_cast<size_t>(height), SampleKind::kNone);
  return blend;
}

// A sample of `color` landed at (x, y): a surface at `depth`, or background at infinity for
// depth 0; its class is covered or background.
void Land(int x, int y, const Eigen::Vector3f& color, float depth, BlendResult* blend, ClassMap* classes) {
  const size_t i = static_cast<size_t>(y) * static_cast<size_t>(classes->width) + static_cast<size_t>(x);
  for (int ch = 0; ch < 3; ++ch) blend->color.At(x, y, ch) = color(ch);
  blend->depth.Values()[i] = depth;
  blend->kind[i] = depth > 0 ? SampleKind::kSurface : SampleKind::kBackground;
  classes->classes[i] = depth > 0 ? PixelClass::kCovered : PixelClass::kBackground;
}

// One row holds two samples, at its two ends, and nothing else anywhere: only the marches
// along the row find them (as a lookup of the row's nearest samples, not a walk), and each
// counts with 1 / its distance. Both at one depth, so both are blended.
TEST(FillHoles, MarchesAlongTheRowWeighTheirSamplesByDistance) {
  constexpr int kWidth = 40, kHeight = 9, kRow = 4;
  BlendResult blend = EmptyBlend(kWidth, kHeight);
  ClassMap classes{kWidth, kHeight,
                   std::vector<PixelClass>(kWidth * kHeight, PixelClass::kDisocclusion), {}};
  Land(0, kRow, kBoxRed, 3, &blend, &classes);
  Land(kWidth - 1, kRow, kWallBlue, 3, &blend, &classes);
  const FillSummary summary =
      FillHoles(classes, MakePinholeCamera(1, kWidth, kHeight, 40, 40, 20, 4.5), {}, &blend);
  // Pixel 20 of the row is 20 from the red sample and 19 from the blue one; beside either end
  // the diagonal marches reach it too, and in the other rows no march finds anything.
  const float red = 1.0f / 20, blue = 1.0f / 19;
  const Eigen::Vector3f expected = (red * kBoxRed + blue * kWallBlue) / (red + blue);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(blend.color.At(20, kRow, ch), expected(ch), 1e-5);
  EXPECT_NEAR(blend.depth.At(20, kRow), 3, 1e-5);
  EXPECT_GE(summary.filled_px, kWidth - 2);
}

// Sky above row 30, ground (blue, depth 5) below, and a 10 x 10 hole just above the ground:
// from its pixels the directions up and along the row (nine of sixteen, more near the hole's
// sides, where shallow marches down leave it sideways) find sky, the others ground. Open to the sky, half the directions suffice for the sky; not open (or with all
// directions asked for), the hole takes the ground, as any hole beside a surface did before.
TEST(FillHoles, HoleOpenToTheSkyTakesItWhereHalfItsDirectionsFindIt) {
  constexpr int kSize = 40, kGround = 30;
  const Eigen::Vector3f sky(0.5f, 0.6f, 0.9f);
  const auto fill = [&](bool open_to_sky, double share) {
    BlendResult blend = EmptyBlend(kSize, kSize);
    ClassMap classes{kSize, kSize, std::vector<PixelClass>(kSize * kSize, PixelClass::kDisocclusion),
                     std::vector<uint8_t>(kSize * kSize, open_to_sky ? 1 : 0)};
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        if (x >= 15 && x < 25 && y >= 20 && y < kGround) continue;
        const bool ground = y >= kGround;
        Land(x, y, ground ? kWallBlue : sky, ground ? 5.0f : 0.0f, &blend, &classes);
      }
    }
    FillOptions options;
    options.hole_sky_share = share;
    FillHoles(classes, MakePinholeCamera(1, kSize, kSize, 40, 40, 20, 20), options, &blend);
    return blend;
  };
  const BlendResult open = fill(true, 0.5), closed = fill(false, 0.5), all = fill(true, 1.0);
  for (int y = 20; y < kGround; ++y) {
    for (int x = 15; x < 25; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(open.color.At(x, y, ch), sky(ch), 1e-4) << x << "," << y;
        EXPECT_NEAR(closed.color.At(x, y, ch), kWallBlue(ch), 1e-5) << x << "," << y;
        EXPECT_NEAR(all.color.At(x, y, ch), kWallBlue(ch), 1e-5) << x << "," << y;
      }
      EXPECT_EQ(open.depth.At(x, y), 0);
      EXPECT_NEAR(closed.depth.At(x, y), 5, 1e-5);
    }
  }
  FillOptions options;
  options.hole_sky_share = 0;
  EXPECT_THROW(options.Check(), UsageError);
}

// Sky in the top rows of the right half, a grey wall (depth 5) below it, and the left half out
// of view. From the left half, some steep marches up and to the right find the sky, the others
// the wall: below the sky's median row the wall goes on (beside the sources' frames a surface
// continues; one patch of sky painted streaks across it), at its rows the sky does.
TEST(FillHoles, OutOfViewBelowTheSkyContinuesTheSurface) {
  constexpr int kSize = 64, kSkyRows = 16;
  const Eigen::Vector3f sky(0.5f, 0.6f, 0.9f), wall(0.4f, 0.4f, 0.4f);
  BlendResult blend = EmptyBlend(kSize, kSize);
  ClassMap classes{kSize, kSize, std::vector<PixelClass>(kSize * kSize, PixelClass::kOutOfView), {}};
  for (int y = 0; y < kSize; ++y) {
    for (int x = kSize / 2; x < kSize; ++x) {
      const bool is_sky = y < kSkyRows;
      Land(x, y, is_sky ? sky : wall, is_sky ? 0.0f : 5.0f, &blend, &classes);
    }
  }
  FillHoles(classes, MakePinholeCamera(1, kSize, kSize, 64, 64, 32, 32), {}, &blend);
  for (int y = kSkyRows; y < kSize; ++y) {
    for (int x = 0; x < kSize / 2; ++x) {
      for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(blend.color.At(x, y, ch), wall(ch), 1e-5) << x << "," << y;
      ASSERT_NEAR(blend.depth.At(x, y), 5, 1e-5);
    }
  }
  for (int y = 0; y < kSkyRows / 2 - 1; ++y) {  // The sky half has every other row sampled.
    for (int x = 0; x < kSize / 2; ++x) ASSERT_EQ(blend.depth.At(x, y), 0) << x << "," << y;
  }
}

// A sky whose color is affine in the direction (y is down: bluer upwards), seen by a source
// looking level and rendered by a target pitched 12 degrees up: the target's top rows are
// sky no source saw.
TEST(FillHoles, SkyNothingSawContinuesTheSkyGradient) {
  const Camera camera = MakePinholeCamera(1, 160, 120, 150, 150, 80, 60);
  test::Scene scene;
  scene.sky = [](const Eigen::Vector3d& d) {
    return Eigen::Vector3f(0.5f + 0.3f * static_cast<float>(d.y()), 0.6f + 0.2f * static_cast<float>(d.y()),
                           0.7f - 0.2f * static_cast<float>(d.y()));
  };
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  const double pitch = 12 * std::numbers::pi / 180;
  const PosedCamera target =
      CameraAt(camera, {0, 0, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitX())));
  const RenderResult result = Render({&source}, target);
  ASSERT_GT(result.metrics.out_of_view_ratio, 0.15);
  double worst = 0, worst_edge_color = 0;
  int checked = 0;
  // The top row of sky the source saw: what copying the edge of the sampled sky would give.
  const Eigen::Vector3f edge = scene.sky(test::PixelRay(source.Posed(), 80, 0).normalized());
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      if (result.classes.At(x, y) != PixelClass::kOutOfView) continue;
      ++checked;
      const Eigen::Vector3f truth = scene.sky(test::PixelRay(target, x, y).normalized());
      for (int ch = 0; ch < 3; ++ch) {
        worst = std::max(worst, static_cast<double>(std::abs(result.color.At(x, y, ch) - truth(ch))));
        worst_edge_color = std::max(worst_edge_color, static_cast<double>(std::abs(edge(ch) - truth(ch))));
      }
      ASSERT_EQ(result.depth.At(x, y), 0);
    }
  }
  EXPECT_GT(checked, 2000);
  // The sky's color is affine in the direction, so the model fits it up to float rounding
  // and the bilinear resampling of the warped sky.
  EXPECT_LT(worst, 0.003);
  EXPECT_GT(worst_edge_color, 0.02);  // What copying the edge would miss it by.
}

// A striped rim (red and blue bands 3 pixels wide, depth 5) along the top of a wide hole: each
// march meets the rim at another band, so unsmoothed the fill fans out in streaks; smoothed, the
// fill far from the rim is close to the rim's mean color and varies little from pixel to pixel,
// while the rows beside the rim keep its bands.
TEST(FillHoles, SmoothedSurfaceFillHasNoStreaks) {
  constexpr int kSize = 64, kRim = 4;
  const auto fill = [&](bool smooth) {
    BlendResult blend = EmptyBlend(kSize, kSize);
    ClassMap classes{kSize, kSize, std::vector<PixelClass>(kSize * kSize, PixelClass::kDisocclusion), {}};
    for (int y = 0; y < kRim; ++y) {
      for (int x = 0; x < kSize; ++x) Land(x, y, (x / 3) % 2 == 0 ? kBoxRed : kWallBlue, 5, &blend, &classes);
    }
    FillOptions options;
    options.smooth = smooth;
    FillHoles(classes, MakePinholeCamera(1, kSize, kSize, 64, 64, 32, 32), options, &blend);
    return blend;
  };
  // Mean absolute difference of red between horizontal neighbours over rows [y0, y1).
  const auto streaks = [&](const BlendResult& blend, int y0, int y1) {
    double sum = 0;
    int count = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = 8; x + 1 < kSize - 8; ++x) {
        sum += static_cast<double>(std::abs(blend.color.At(x + 1, y, 0) - blend.color.At(x, y, 0)));
        ++count;
      }
    }
    return sum / count;
  };
  const BlendResult raw = fill(false), smooth = fill(true);
  ASSERT_GT(streaks(raw, 24, 56), 0.02);
  EXPECT_LT(streaks(smooth, 24, 56), 0.05 * streaks(raw, 24, 56));
  const float rim_red = 0.5f * (kBoxRed(0) + kWallBlue(0));
  EXPECT_NEAR(smooth.color.At(kSize / 2, 48, 0), rim_red, 0.03);
  // Beside the rim the fill is left as the marches made it.
  for (int x = 0; x < kSize; ++x) EXPECT_EQ(smooth.color.At(x, kRim, 0), raw.color.At(x, kRim, 0));
}

}  // namespace
}  // namespace parallax

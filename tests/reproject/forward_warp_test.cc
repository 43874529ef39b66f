#include "reproject/forward_warp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "reproject/background.h"
#include "reproject/render.h"
#include "tests/reproject/analytic_scene.h"

namespace parallax {
namespace {
using test::CameraAt;
using test::Scene;

Camera TestCamera(int width = 160, int height = 120, double focal = 150) {
  return MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height), focal,
                           focal, width / 2.0, height / 2.0);
}

// A red box 4..5 in front of the camera.
test::Box RedBox() {
  return {{-0.5, -0.4, 4}, {0.5, 0.4, 5}, test::WavyTexture({0.7f, 0.2f, 0.1f}, 0.3)};
}

// The red box in front of a blue wall at 8.
Scene BoxScene() {
  Scene scene;
  scene.planes.push_back(test::WallAt(8, test::WavyTexture({0.1f, 0.2f, 0.7f}, 0.8)));
  scene.boxes.push_back(RedBox());
  return scene;
}

TEST(ForwardWarp, IdentityPoseReproducesSourceForBothMethods) {
  const PosedCamera camera = CameraAt(TestCamera(), {0, 0, 0});
  const SourceView source = test::RenderView(BoxScene(), camera);
  for (WarpMethod method : {WarpMethod::kMesh, WarpMethod::kSplat}) {
    ForwardWarpOptions options;
    options.method = method;
    WarpBuffer buffer;
    ForwardWarp(source, camera, options, &buffer);
    double max_color_error_scaled = 0, max_depth_error = 0;
    for (int y = 0; y < 120; ++y) {
      for (int x = 0; x < 160; ++x) {
        const size_t i = static_cast<size_t>(y * 160 + x);
        ASSERT_GT(buffer.Depth(i), 0) << x << "," << y;
        max_depth_error = std::max(max_depth_error,
                                   std::abs(static_cast<double>(buffer.Depth(i) - source.depth.At(x, y))) /
                                       static_cast<double>(source.depth.At(x, y)));
        for (int c = 0; c < 3; ++c) {
          // Relative to the value's half rounding (WarpBuffer::ColorWeights).
          const double error = std::abs(buffer.Color(i)[c] - source.color.At(x, y, c));
          max_color_error_scaled = std::max(max_color_error_scaled, error / (1e-4 + WarpBuffer::kHalfRounding * static_cast<double>(source.color.At(x, y, c))));
        }
      }
    }
    EXPECT_LT(max_depth_error, 1e-5);
    EXPECT_LT(max_color_error_scaled, 1);
  }
}

TEST(ForwardWarp, MeshDropsTrianglesAcrossDepthDiscontinuities) {
  const Camera camera = TestCamera();
  const Scene scene = BoxScene();
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  const PosedCamera target = CameraAt(camera, {0.4, 0.1, 0});
  ForwardWarpOptions options;
  options.method = WarpMethod::kMesh;
  WarpBuffer buffer;
  ForwardWarp(source, target, options, &buffer);
  int intermediate = 0, surface = 0;
  for (size_t i = 0; i < buffer.Size(); ++i) {
    const float z = buffer.Depth(i);
    if (z == 0) continue;
    ++surface;
    // The box front is at z 4 and the wall at 8: a rubber sheet between them would land here.
    if (z > 4.04f && z < 7.92f) ++intermediate;
  }
  EXPECT_GT(surface, 160 * 120 / 2);
  EXPECT_EQ(intermediate, 0);
}

// Source pixels with an 8-neighbour across a depth step (the box's outline, on the box and on
// the wall) against those farther from any: identity warp, so every target pixel holds its
// own source pixel's sample, whose ray angle is 0. A block (up to 4 x 4 pixels) is drawn from
// its corners: on its edges and inside, the penalty of a corner on the outline fades with the
// distance from it, so an outline pixel midway along a block's edge has a quarter of it or
// more, and pixels up to 4 from the outline some.
TEST(ForwardWarp, SilhouetteSamplesWeighLess) {
  const PosedCamera camera = CameraAt(TestCamera(), {0, 0, 0});
  const SourceView source = test::RenderView(BoxScene(), camera);
  const auto step_within = [&](int x, int y, int reach) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        const int u = std::clamp(x + dx, 0, 159), v = std::clamp(y + dy, 0, 119);
        if (std::abs(source.depth.At(u, v) - source.depth.At(x, y)) > 1) return true;
      }
    }
    return false;
  };
  for (double penalty : {0.0, 0.5}) {
    ForwardWarpOptions options;
    options.silhouette_angle_rad = penalty;
    WarpBuffer buffer;
    ForwardWarp(source, camera, options, &buffer);
    const double interior = 1 / options.angle_epsilon_rad;
    const double silhouette = 1 / (options.angle_epsilon_rad + penalty);
    int outline = 0;
    for (int y = 0; y < 120; ++y) {
      for (int x = 0; x < 160; ++x) {
        const double weight = buffer.Weight(static_cast<size_t>(y * 160 + x));
        if (step_within(x, y, 1)) {
          ++outline;
          const double quarter = 1 / (options.angle_epsilon_rad + penalty / 4);
          EXPECT_TRUE(weight >= silhouette * 0.999 && weight <= quarter * 1.001) << weight;
        } else if (!step_within(x, y, 4)) {
          EXPECT_NEAR(weight, interior, 1e-3 * interior) << x << "," << y;
        } else {
          EXPECT_TRUE(weight >= silhouette * 0.999 && weight <= interior * 1.001) << weight;
        }
      }
    }
    // The box spans ~38 x 30 pixels: its outline, inside and out, ~2 x 136 pixels.
    EXPECT_GT(outline, 250);
  }
  ForwardWarpOptions options;
  options.silhouette_angle_rad = -0.1;
  EXPECT_THROW(options.Check(), UsageError);
}

// The box's front face (z 4) spans source columns 61.25..98.75 and rows 45..75 (pixel
// coordinates); the target is the source camera with its principal point half a pixel to the
// right, so the face's outline falls halfway between target pixel centres: 37 columns (62 to
// 98) x 30 rows have their centres on it. The mesh reaches the outermost samples, now 0.5
// pixel short of a centre on either side; their full footprint (0.55 pixel either way) takes
// one more column on each side, a share of 0.6 does not, and the wall's samples beside the
// outline (1.4 of theirs) cover those columns: no hole opens.
// The test camera with its principal point half a pixel to the right: every source sample of
// an identity warp lands halfway between two target pixel centres.
PosedCamera HalfPixelRight() {
  return CameraAt(MakePinholeCamera(1, 160, 120, 150, 150, 80.5, 60), {0, 0, 0});
}

// A sample of a surface at depth 4 (the box's front face, the pole).
bool AtDepth4(float depth) { return std::abs(depth - 4.0f) < 0.01f; }

TEST(ForwardWarp, OutlineSamplesSplatAShareOfTheirFootprint) {
  const SourceView source = test::RenderView(BoxScene(), CameraAt(TestCamera(), {0, 0, 0}));
  const PosedCamera target = HalfPixelRight();
  const auto front_face_pixels = [&](double share) {
    ForwardWarpOptions options;
    options.outline_splat_share = share;
    WarpBuffer buffer;
    ForwardWarp(source, target, options, &buffer);
    int count = 0, holes = 0;
    for (size_t i = 0; i < buffer.Size(); ++i) {
      count += AtDepth4(buffer.Depth(i)) ? 1 : 0;
      holes += buffer.Depth(i) == 0 ? 1 : 0;
    }
    EXPECT_EQ(holes, 0) << share;
    return count;
  };
  EXPECT_EQ(front_face_pixels(0.6), 37 * 30);
  EXPECT_EQ(front_face_pixels(1.0), 39 * 30);
  ForwardWarpOptions options;
  options.outline_splat_share = 0;
  EXPECT_THROW(options.Check(), UsageError);
  options.outline_splat_share = 1.5;
  EXPECT_THROW(options.Check(), UsageError);
}

// A pole one source column wide (x 0.01..0.03 at z 4: only column 80's centre, 80.5, lies on
// it) in front of the wall, seen with the principal point half a pixel to the right: its
// samples land halfway between two target columns. Its outline on both sides would shrink its
// footprint to 0.66 pixel, which holds no pixel centre; one sample wide, it keeps the full
// 1.1 and shows in every row.
TEST(ForwardWarp, StructuresOneSampleWideKeepTheirFootprint) {
  Scene scene;
  scene.planes.push_back(test::WallAt(8, test::WavyTexture({0.1f, 0.2f, 0.7f}, 0.8)));
  scene.boxes.push_back({{0.01, -0.4, 4}, {0.03, 0.4, 5}, test::WavyTexture({0.7f, 0.2f, 0.1f}, 0.3)});
  const SourceView source = test::RenderView(scene, CameraAt(TestCamera(), {0, 0, 0}));
  const PosedCamera target = HalfPixelRight();
  WarpBuffer buffer;
  ForwardWarp(source, target, {}, &buffer);
  // Rows 45..74 have their centres on the pole (y -0.4..0.4 at z 4).
  for (int y = 45; y < 75; ++y) {
    int pole = 0;
    for (int x = 78; x < 84; ++x) pole += AtDepth4(buffer.Depth(static_cast<size_t>(y * 160 + x))) ? 1 : 0;
    EXPECT_EQ(pole, 2) << y;
  }
}

TEST(ForwardWarp, PointsAtOrBehindTheTargetAreDropped) {
  const Camera camera = TestCamera();
  const SourceView source = test::RenderView(BoxScene(), CameraAt(camera, {0, 0, 0}));
  // Between box and wall, looking back at the box: the wall is behind the camera.
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()));
  const PosedCamera target = CameraAt(camera, {0, 0, 6}, turn);
  for (WarpMethod method : {WarpMethod::kMesh, WarpMethod::kSplat}) {
    ForwardWarpOptions options;
    options.method = method;
    WarpBuffer buffer;
    ForwardWarp(source, target, options, &buffer);
    for (size_t i = 0; i < buffer.Size(); ++i) {
      const float z = buffer.Depth(i);
      ASSERT_TRUE(z == 0 || (z > 0 && std::isfinite(z))) << z;
      // Only the box (its front face seen from behind, 1..2 away) can be in front.
      if (z > 0) {
        EXPECT_LT(z, 2.01f);
        EXPECT_TRUE(std::isfinite(buffer.Color(i)[0]));
      }
    }
  }
}

Eigen::Vector3f SkyColor(const Eigen::Vector3d& dir) {
  return Eigen::Vector3f(static_cast<float>(0.5 + 0.4 * dir.x() / dir.z()),
                         static_cast<float>(0.5 + 0.4 * dir.y() / dir.z()), 0.3f);
}

// The red box against the sky.
Scene BoxInSky() {
  Scene scene;
  scene.boxes.push_back(RedBox());
  scene.sky = SkyColor;
  return scene;
}

TEST(ForwardWarp, SkyWarpsAsDirectionsUnderPureRotation) {
  const Camera camera = TestCamera(160, 120, 150);
  const Scene scene = BoxInSky();
  const PosedCamera source_camera = CameraAt(camera, {0, 0, 0});
  const SourceView source = test::RenderView(scene, source_camera);
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.08, Eigen::Vector3d(0.2, 1, 0.1).normalized()));
  const PosedCamera target = CameraAt(camera, {0, 0, 0}, rotation);
  RenderOptions options;
  options.fill.method = FillMethod::kNone;
  const RenderResult result = Render({&source}, target, options);

  int checked = 0, wrong_class = 0;
  double max_error_scaled = 0;
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const Eigen::Vector3d dir = test::PixelRay(target, x, y);
      // Where the source sees this direction; skip its border and the box's silhouette.
      const double su = 150 * dir.x() / dir.z() + 80, sv = 150 * dir.y() / dir.z() + 60;
      if (su < 1.5 || sv < 1.5 || su > 158.5 || sv > 118.5) continue;
      bool near_box = false;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          near_box = near_box || scene.Intersect(Eigen::Vector3d::Zero(), test::PixelRay(target, x + dx, y + dy)).has_value();
        }
      }
      if (near_box) continue;
      ++checked;
      if (result.classes.At(x, y) != PixelClass::kBackground) {
        ++wrong_class;
        continue;
      }
      // Decode the direction the color came from and compare in source pixels.
      // Over 0.02 pixels plus the error of the color's half roundings in pixels (texture and
      // warp buffer).
      const double red = result.color.At(x, y, 0), green = result.color.At(x, y, 1);
      const double du = 150 * (red - 0.5) / 0.4 - 150 * dir.x() / dir.z();
      const double dv = 150 * (green - 0.5) / 0.4 - 150 * dir.y() / dir.z();
      const double rounding_px = 150 / 0.4 * 2 * WarpBuffer::kHalfRounding * std::hypot(red, green);
      max_error_scaled = std::max(max_error_scaled, std::hypot(du, dv) / (0.02 + rounding_px));
    }
  }
  EXPECT_GT(checked, 160 * 120 / 2);
  EXPECT_EQ(wrong_class, 0);
  EXPECT_LT(max_error_scaled, 1);
  EXPECT_EQ(result.metrics.disocclusion_ratio, 0);
  // Background never reaches the depth map.
  for (float z : result.depth.Values()) ASSERT_TRUE(std::isfinite(z));
}

// A source's own background mask and texture (PrepareSource) warp exactly as those the warp
// makes itself; a mask made with another color step is not used.
TEST(ForwardWarp, SourceBackgroundMaskIsUsedOnlyForItsStep) {
  const Camera camera = TestCamera(160, 120, 150);
  const Scene scene = BoxInSky();
  SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  const PosedCamera target = CameraAt(camera, {0.3, -0.1, 0.2});
  const auto warp = [&](const SourceView& view) {
    WarpBuffer buffer;
    WarpScratch scratch;
    ForwardWarp(view, target, {}, &buffer, &scratch);
    std::vector<float> samples;  // Depth, color and weight of every pixel with a sample.
    for (size_t i = 0; i < buffer.Size(); ++i) {
      if (buffer.Depth(i) == 0) continue;
      const std::array<float, 3> rgb = buffer.Color(i);
      samples.insert(samples.end(), {buffer.Depth(i), rgb[0], rgb[1], rgb[2], buffer.Weight(i)});
    }
    return std::make_pair(samples, scratch.Background());
  };
  const auto [own_samples, own_mask] = warp(source);
  ASSERT_GT(std::count(own_mask.begin(), own_mask.end(), 1), 160 * 120 / 2);

  PrepareSource(&source);
  EXPECT_EQ(source.background, own_mask);
  ASSERT_EQ(source.texture.size(), 4u * 160 * 120);
  const auto [shared_samples, shared_mask] = warp(source);
  EXPECT_EQ(shared_samples, own_samples);

  // A stale mask (everything background) made with another step: the warp marks its own.
  std::fill(source.background.begin(), source.background.end(), uint8_t{1});
  source.background_step = 0.5f;
  const auto [restep_samples, restep_mask] = warp(source);
  EXPECT_EQ(restep_mask, own_mask);
  EXPECT_EQ(restep_samples, own_samples);
}

// A warp drawn in bands of target rows in parallel gives what one band gives, bit for bit:
// every band draws its rows in the same order (z-test ties alike), and a row-end group does
// not touch the next band's first pixels. Odd band counts put band edges on odd rows; the
// box in the sky has silhouettes, splats and background crossing them.
TEST(ForwardWarp, BandsDrawWhatOneBandDraws) {
  const Camera camera = TestCamera(161, 121, 150);
  SourceView source = test::RenderView(BoxInSky(), CameraAt(camera, {0, 0, 0}));
  const PosedCamera target = CameraAt(camera, {0.3, -0.1, 0.2});
  for (const WarpMethod method : {WarpMethod::kMesh, WarpMethod::kSplat}) {
    ForwardWarpOptions options;
    options.method = method;
    WarpBuffer one;
    ForwardWarp(source, target, options, &one);
    const size_t size = one.Size();
    ASSERT_GT(std::count_if(one.Depths(), one.Depths() + size, [](float z) { return z > 0; }),
              static_cast<long>(size / 4));
    for (const int bands : {2, 3, 7, 500}) {
      WarpBuffer banded;
      WarpScratch scratch;
      ForwardWarp(source, target, options, &banded, &scratch, bands);
      ASSERT_EQ(banded.Size(), size);
      size_t differ = 0;
      for (size_t i = 0; i < size; ++i) {
        if (std::memcmp(banded.Depths() + i, one.Depths() + i, sizeof(float)) != 0) {
          ++differ;
          continue;
        }
        if (one.Depth(i) == 0) continue;  // Color and weight mean nothing there.
        differ += std::memcmp(banded.ColorWeights() + 4 * i, one.ColorWeights() + 4 * i,
                              4 * sizeof(uint16_t)) != 0;
      }
      EXPECT_EQ(differ, 0u) << "bands " << bands << ", method " << static_cast<int>(method);
    }
  }
}

TEST(ForwardWarp, EnclosedDepthZeroIsAHoleNotBackground) {
  const Camera camera = TestCamera();
  SourceView source = test::RenderView(BoxScene(), CameraAt(camera, {0, 0, 0}));
  for (int y = 55; y < 65; ++y) {
    for (int x = 75; x < 85; ++x) source.depth.At(x, y) = 0;  // Inside the box face.
  }
  RenderOptions options;
  options.fill.method = FillMethod::kNone;
  const RenderResult result = Render({&source}, CameraAt(camera, {0, 0, 0}), options);
  EXPECT_EQ(test::CountClass(result.classes, PixelClass::kBackground), 0);
  for (int y = 56; y < 64; ++y) {
    for (int x = 76; x < 84; ++x) EXPECT_TRUE(IsHole(result.classes.At(x, y))) << x << "," << y;
  }
}

// A wall with stripes 4 pixels apart, seen from half a pixel to the side: every target pixel
// samples its source between two pixels, where bilinear interpolation averages the stripe
// away (a 4-pixel period keeps cos 45 deg = 71% of its contrast) and Catmull-Rom keeps 88%.
TEST(ForwardWarp, BicubicTextureFilterKeepsFineTextureSharper) {
  const double depth = 4, focal = 150, period_px = 4;
  const double pixel_m = depth / focal;
  Scene scene;
  scene.planes.push_back(test::WallAt(depth, [&](const Eigen::Vector3d& p) {
    const double phase = 2 * std::numbers::pi * p.x() / (period_px * pixel_m);
    const float stripe = static_cast<float>(0.3 * std::sin(phase));
    return Eigen::Vector3f(0.5f + stripe, 0.5f, 0.5f - stripe);
  }));
  const SourceView source = test::RenderView(scene, CameraAt(TestCamera(), {0, 0, 0}));
  const PosedCamera target = CameraAt(TestCamera(), {0.5 * pixel_m, 0, 0});
  const SourceView truth = test::RenderView(scene, target);
  const auto rms_error = [&](TextureFilter filter) {
    ForwardWarpOptions options;
    options.texture_filter = filter;
    WarpBuffer buffer;
    ForwardWarp(source, target, options, &buffer);
    double sum = 0;
    int count = 0;
    for (int y = 4; y < 116; ++y) {
      for (int x = 4; x < 156; ++x) {
        const size_t i = static_cast<size_t>(y * 160 + x);
        EXPECT_GT(buffer.Depth(i), 0) << x << "," << y;
        const double error = buffer.Color(i)[0] - truth.color.At(x, y, 0);
        sum += error * error;
        ++count;
      }
    }
    return std::sqrt(sum / count);
  };
  const double bilinear = rms_error(TextureFilter::kAuto);
  const double bicubic = rms_error(TextureFilter::kBicubic);
  // Contrast lost: 0.3 x (1 - 0.71) = 0.088 at the peaks (RMS 0.062) and 0.3 x 0.12 (0.025).
  EXPECT_NEAR(bilinear, 0.062, 0.005);
  EXPECT_NEAR(bicubic, 0.025, 0.004);
}

// A slanted plane whose source depth grows 2.8-fold down the image (2.7 to 7.7), so an 8x8
// block spans ~7% of depth: its texture must land where the geometry says (3e-5 px off; the
// two triangles per 4x4 block before the projective map missed by 0.056 px, interpolating the
// source position affinely). The source's color is its own pixel coordinate (a ramp, which
// bilinear and Catmull-Rom sampling both reproduce).
TEST(ForwardWarp, MeshTextureFollowsTheSourceProjectionAcrossASlantedPlane) {
  const Camera camera = TestCamera();
  const double f = camera.FocalX(), cx = camera.PrincipalX(), cy = camera.PrincipalY();
  const Eigen::Vector3d normal(0, 0.3, 0.25);  // The plane normal . X = 1 (source frame).
  SourceView source{"slanted", camera, Rigid3d(), Image(160, 120, 3), DepthMap(160, 120), {}, 0, {}};
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const Eigen::Vector3d ray((x + 0.5 - cx) / f, (y + 0.5 - cy) / f, 1);
      source.depth.At(x, y) = static_cast<float>(1 / normal.dot(ray));
      source.color.At(x, y, 0) = static_cast<float>(x) / 256;
      source.color.At(x, y, 1) = static_cast<float>(y) / 256;
    }
  }
  const Eigen::Vector3d centre(0.15, -0.1, 0.2);
  const PosedCamera target = CameraAt(camera, centre);
  WarpBuffer buffer;
  ForwardWarp(source, target, {}, &buffer);
  double position_error_scaled = 0, depth_error = 0;
  int checked = 0;
  for (int ty = 0; ty < 120; ++ty) {
    for (int tx = 0; tx < 160; ++tx) {
      const size_t i = static_cast<size_t>(ty * 160 + tx);
      if (buffer.Depth(i) == 0) continue;
      const Eigen::Vector3d ray((tx + 0.5 - cx) / f, (ty + 0.5 - cy) / f, 1);
      const Eigen::Vector3d point = centre + (1 - normal.dot(centre)) / normal.dot(ray) * ray;
      // Source pixel coordinates (column, row) of the point; the border's splats are its
      // own samples, so only points a pixel and a half inside are compared.
      const double sx = f * point.x() / point.z() + cx - 0.5;
      const double sy = f * point.y() / point.z() + cy - 0.5;
      if (sx < 1.5 || sy < 1.5 || sx > 157.5 || sy > 117.5) continue;
      // Over 0.01 pixels plus the color's half roundings in pixels (texture and warp buffer).
      const double red = buffer.Color(i)[0], green = buffer.Color(i)[1];
      const auto bound = [](double value) { return 0.01 + 256 * 2 * WarpBuffer::kHalfRounding * value; };
      position_error_scaled = std::max({position_error_scaled, std::abs(red * 256 - sx) / bound(red),
                                 std::abs(green * 256 - sy) / bound(green)});
      const double z = buffer.Depth(i);
      depth_error = std::max(depth_error, std::abs(z / (point.z() - centre.z()) - 1));
      ++checked;
    }
  }
  EXPECT_GT(checked, 12000);
  EXPECT_LT(position_error_scaled, 1);
  EXPECT_LT(depth_error, 1e-4);
}

TEST(ForwardWarp, RejectsDistortedCamerasAndBadOptions) {
  SourceView source = test::RenderView(BoxScene(), CameraAt(TestCamera(), {0, 0, 0}));
  source.camera.model = CameraModel::kSimpleRadial;
  source.camera.params = {150, 80, 60, 0.1};
  WarpBuffer buffer;
  EXPECT_THROW(ForwardWarp(source, CameraAt(TestCamera(), {0, 0, 0}), {}, &buffer),
               InternalError);
  ForwardWarpOptions options;
  options.max_slant_deg = 90;
  EXPECT_THROW(options.Check(), UsageError);
  source.camera = TestCamera(100, 120);
  EXPECT_THROW(CheckSourceView(source), InternalError);
}

}  // namespace
}  // namespace parallax

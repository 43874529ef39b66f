#include "reproject/render.h"

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "reproject/novel_views.h"
#include "reproject/source_selection.h"
#include "tests/reproject/analytic_scene.h"

namespace parallax {
namespace {
using test::CameraAt;
using test::Scene;

constexpr WarpMethod kMethods[] = {WarpMethod::kMesh, WarpMethod::kSplat};

RenderOptions Options(WarpMethod method, FillMethod fill = FillMethod::kNone) {
  RenderOptions options;
  options.warp.method = method;
  options.fill.method = fill;
  return options;
}

const char* Name(WarpMethod method) { return method == WarpMethod::kMesh ? "mesh" : "splat"; }

// 400x300, f 400: a red box (x, y in +-1 x +-0.75, z 4..5) in front of a blue wall at z 8.
Camera BoxCamera() { return MakePinholeCamera(1, 400, 300, 400, 400, 200, 150); }
Scene BoxScene() {
  Scene scene;
  scene.planes.push_back(test::WallAt(8, test::WavyTexture({0.1f, 0.2f, 0.7f}, 1.0)));
  scene.boxes.push_back({{-1, -0.75, 4}, {1, 0.75, 5}, test::WavyTexture({0.7f, 0.2f, 0.1f}, 0.4)});
  return scene;
}

// Target pixels on the wall, inside the source's image, whose wall point the box hides from
// the source: the disocclusion by ray casting.
long TrueDisocclusion(const Scene& scene, const PosedCamera& source, const PosedCamera& target) {
  const Eigen::Vector3d source_center = CameraCenter(source.cam_from_world);
  const Eigen::Vector3d target_center = CameraCenter(target.cam_from_world);
  long count = 0;
  for (int y = 0; y < static_cast<int>(target.camera.height); ++y) {
    for (int x = 0; x < static_cast<int>(target.camera.width); ++x) {
      const std::optional<test::Hit> hit = scene.Intersect(target_center, test::PixelRay(target, x, y));
      if (!hit || hit->box) continue;
      const std::optional<Eigen::Vector2d> pixel =
          source.camera.Project(source.cam_from_world * hit->point);
      if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > source.camera.width ||
          pixel->y() > source.camera.height) {
        continue;
      }
      if (scene.Occluded(source_center, hit->point)) ++count;
    }
  }
  return count;
}

TEST(Render, PlaneMovedSidewaysHasNoHolesAndAnOutOfViewStrip) {
  const Camera camera = MakePinholeCamera(1, 320, 240, 300, 300, 160, 120);
  Scene scene;
  // 24 target pixels per texture period at depth 5.
  scene.planes.push_back(test::WallAt(5, test::WavyTexture({0.45f, 0.4f, 0.35f}, 0.4)));
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  // 15.5 px of disparity: the right 15.5 px of the target are not in the source.
  const double baseline = 15.5 * 5 / 300;
  const PosedCamera target = CameraAt(camera, {baseline, 0, 0});
  const SourceView truth = test::RenderView(scene, target);
  for (WarpMethod method : kMethods) {
    SCOPED_TRACE(Name(method));
    const RenderResult result = Render({&source}, target, Options(method));
    EXPECT_LT(result.metrics.hole_ratio, 0.001);
    EXPECT_NEAR(result.metrics.out_of_view_ratio, 15.5 / 320, 0.05 * 15.5 / 320);
    EXPECT_EQ(result.metrics.background_ratio, 0);
    const double psnr = test::PsnrSrgb(result.color, truth.color, [&](int x, int y) {
      return result.classes.At(x, y) == PixelClass::kCovered;
    });
    EXPECT_GE(psnr, 30);
    for (int y = 0; y < 240; ++y) {
      EXPECT_EQ(result.classes.At(319, y), PixelClass::kOutOfView);
      EXPECT_EQ(result.classes.At(300, y), PixelClass::kCovered);
    }
  }
}

TEST(Render, FillingIsSkippedWhenNothingIsMissing) {
  const Camera camera = MakePinholeCamera(1, 160, 120, 150, 150, 80, 60);
  Scene scene;
  scene.planes.push_back(test::WallAt(5, test::WavyTexture({0.45f, 0.4f, 0.35f}, 0.4)));
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  // The source's own camera: every pixel covered, nothing to fill.
  const RenderResult same = Render({&source}, source.Posed(), Options(WarpMethod::kMesh));
  EXPECT_EQ(same.metrics.hole_ratio + same.metrics.out_of_view_ratio, 0.0);
  EXPECT_EQ(same.fill.skipped, "no holes to fill");
  EXPECT_EQ(same.fill.filled_px, 0);
  // Moved sideways: an out-of-view strip to fill, so filling runs, unless none was asked for.
  const PosedCamera target = CameraAt(camera, {0.3, 0, 0});
  const RenderResult moved = Render({&source}, target, Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  EXPECT_GT(moved.metrics.out_of_view_ratio, 0.05);
  EXPECT_TRUE(moved.fill.skipped.empty());
  EXPECT_GT(moved.fill.filled_px, 0);
  EXPECT_EQ(Render({&source}, target, Options(WarpMethod::kMesh)).fill.skipped, "not requested (fill none)");
}

TEST(Render, BoxInFrontOfWallDisocclusionMatchesRayCasting) {
  const Scene scene = BoxScene();
  const PosedCamera source_camera = CameraAt(BoxCamera(), {0, 0, 0});
  const SourceView source = test::RenderView(scene, source_camera);
  // 40 px more disparity on the box than on the wall: a 40 px wide disocclusion.
  const PosedCamera target = CameraAt(BoxCamera(), {0.8, 0, 0});
  const long truth = TrueDisocclusion(scene, source_camera, target);
  ASSERT_GT(truth, 5000);
  for (WarpMethod method : kMethods) {
    SCOPED_TRACE(Name(method));
    const RenderResult result = Render({&source}, target, Options(method));
    const long disocclusion = test::CountClass(result.classes, PixelClass::kDisocclusion);
    const long holes = disocclusion + test::CountClass(result.classes, PixelClass::kCrack);
    EXPECT_NEAR(static_cast<double>(disocclusion), static_cast<double>(truth), 0.04 * static_cast<double>(truth));
    EXPECT_NEAR(static_cast<double>(holes), static_cast<double>(truth), 0.04 * static_cast<double>(truth));
    EXPECT_EQ(result.metrics.hole_count, 1);
    EXPECT_NEAR(result.metrics.largest_hole_px, holes, 0);
  }
}

// The sky may lie behind what the source saw in a hole's direction, not where it saw
// something there without knowing its depth. Target and source differ by a translation only,
// so the direction of target pixel (x, y) is source pixel (x, y). As rendered, every
// disocclusion looks at the box in the source (open); with the box's depth removed, the holes
// whose direction falls on it are not open, the others are.
TEST(Render, HolesAreOpenToTheSkyUnlessTheSourceSawTheirDirectionWithoutDepth) {
  SourceView source = test::RenderView(BoxScene(), CameraAt(BoxCamera(), {0, 0, 0}));
  const PosedCamera target = CameraAt(BoxCamera(), {0.8, 0, 0});
  RenderOptions options = Options(WarpMethod::kMesh);
  options.warp.background_at_infinity = false;
  // Hole pixels, and those of them whose source pixel has no depth.
  const auto count_holes = [&](long* closed) {
    const RenderResult result = Render({&source}, target, options);
    long holes = 0;
    *closed = 0;
    for (int y = 0; y < 300; ++y) {
      for (int x = 0; x < 400; ++x) {
        if (!IsHole(result.classes.At(x, y))) continue;
        ++holes;
        const bool unknown = source.depth.At(x, y) == 0;
        EXPECT_EQ(result.classes.OpenToSky(x, y), !unknown) << x << "," << y;
        *closed += unknown ? 1 : 0;
      }
    }
    return holes;
  };
  long closed = 0;
  EXPECT_GT(count_holes(&closed), 5000);
  EXPECT_EQ(closed, 0);
  for (float& depth : source.depth.Values()) depth = depth < 6 ? 0.0f : depth;
  EXPECT_GT(count_holes(&closed), 5000);
  EXPECT_GT(closed, 5000);
}

TEST(Render, PureRotationHasNoDisocclusion) {
  const Scene scene = BoxScene();
  const SourceView source = test::RenderView(scene, CameraAt(BoxCamera(), {0, 0, 0}));
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.3, 1, 0).normalized()));
  const PosedCamera target = CameraAt(BoxCamera(), {0, 0, 0}, rotation);
  const SourceView truth = test::RenderView(scene, target);
  for (WarpMethod method : kMethods) {
    SCOPED_TRACE(Name(method));
    const RenderResult result = Render({&source}, target, Options(method));
    EXPECT_EQ(result.metrics.disocclusion_ratio, 0);
    EXPECT_LT(result.metrics.crack_ratio, 0.001);
    EXPECT_GT(result.metrics.out_of_view_ratio, 0.05);
    const double psnr = test::PsnrSrgb(result.color, truth.color, [&](int x, int y) {
      return result.classes.At(x, y) == PixelClass::kCovered;
    });
    EXPECT_GE(psnr, 30);
  }
}

TEST(Render, TwoSourcesOnEitherSideShrinkTheHoles) {
  const Scene scene = BoxScene();
  const SourceView left = test::RenderView(scene, CameraAt(BoxCamera(), {-0.6, 0, 0}), "left");
  const SourceView right = test::RenderView(scene, CameraAt(BoxCamera(), {0.6, 0, 0}), "right");
  const PosedCamera target = CameraAt(BoxCamera(), {0, 0.05, 0});
  const SourceView truth = test::RenderView(scene, target);
  for (WarpMethod method : kMethods) {
    SCOPED_TRACE(Name(method));
    const RenderResult one = Render({&left}, target, Options(method));
    const RenderResult both = Render({&left, &right}, target, Options(method));
    EXPECT_GT(one.metrics.hole_ratio, 0.01);
    EXPECT_LT(both.metrics.hole_ratio, 0.1 * one.metrics.hole_ratio);
    EXPECT_LT(both.metrics.out_of_view_ratio, one.metrics.out_of_view_ratio);
    const double psnr = test::PsnrSrgb(both.color, truth.color, [&](int x, int y) {
      return both.classes.At(x, y) == PixelClass::kCovered;
    });
    EXPECT_GE(psnr, 30);
  }
}

// One more source added to a render warps only that source and gives what rendering all of
// them at once gives.
TEST(Renderer, RenderWithOneMoreEqualsRenderingAllSources) {
  const Scene scene = BoxScene();
  const SourceView left = test::RenderView(scene, CameraAt(BoxCamera(), {-0.6, 0, 0}), "left");
  const SourceView right = test::RenderView(scene, CameraAt(BoxCamera(), {0.6, 0, 0}), "right");
  const SourceView up = test::RenderView(scene, CameraAt(BoxCamera(), {0, 0.5, 0}), "up");
  const PosedCamera target = CameraAt(BoxCamera(), {0, 0.05, 0});
  Renderer renderer(Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  RenderResult added;
  EXPECT_THROW(renderer.RenderWithOneMore(up, &added), std::logic_error);
  renderer.Render({&left, &right}, target, &added);
  renderer.RenderWithOneMore(up, &added);
  const RenderResult all = Render({&left, &right, &up}, target, Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  EXPECT_EQ(added.color.Pixels(), all.color.Pixels());
  EXPECT_EQ(added.depth.Values(), all.depth.Values());
  EXPECT_EQ(added.metrics.hole_ratio, all.metrics.hole_ratio);

  // The renderer keeps the added source's buffer for the next view: a render from fewer
  // sources must not blend it in, and adding the source again must warp it afresh.
  RenderResult two;
  renderer.Render({&left, &right}, target, &two);
  const RenderResult fresh = Render({&left, &right}, target, Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  EXPECT_EQ(two.color.Pixels(), fresh.color.Pixels());
  EXPECT_EQ(two.metrics.hole_ratio, fresh.metrics.hole_ratio);
  EXPECT_NE(two.metrics.hole_ratio, all.metrics.hole_ratio);  // "up" makes a difference.
  renderer.RenderWithOneMore(up, &two);
  EXPECT_EQ(two.color.Pixels(), all.color.Pixels());
}

// A camera path renders into one result, whose memory each frame reuses: nothing of an
// earlier frame (another view, other holes) may show through.
TEST(Renderer, FramesIntoOneResultEqualFreshRenders) {
  const Scene scene = BoxScene();
  const SourceView left = test::RenderView(scene, CameraAt(BoxCamera(), {-0.6, 0, 0}), "left");
  const SourceView right = test::RenderView(scene, CameraAt(BoxCamera(), {0.6, 0, 0}), "right");
  const PosedCamera near = CameraAt(BoxCamera(), {0, 0.05, 0});
  const PosedCamera far = CameraAt(BoxCamera(), {1.5, 0.4, 0});
  const RenderOptions options = Options(WarpMethod::kMesh, FillMethod::kDepthAware);
  Renderer renderer(options);
  RenderResult frame;
  for (const PosedCamera* target : {&far, &near, &far, &near}) {
    renderer.Render({&left, &right}, *target, &frame);
  }
  const RenderResult fresh = Render({&left, &right}, near, options);
  EXPECT_EQ(frame.color.Pixels(), fresh.color.Pixels());
  EXPECT_EQ(frame.depth.Values(), fresh.depth.Values());
  EXPECT_EQ(frame.classes.classes, fresh.classes.classes);
  EXPECT_EQ(frame.metrics.hole_ratio, fresh.metrics.hole_ratio);
  // The far view's holes differ from the near view's: the test compares different frames.
  renderer.Render({&left, &right}, far, &frame);
  EXPECT_NE(frame.metrics.hole_ratio, fresh.metrics.hole_ratio);
}

// The hole a box leaves in a render from its left lies behind the box: of three more
// cameras, the one to the right sees it, one further left and one looking away do not.
TEST(SourceSeeingMost, PicksTheViewThatSeesBehindTheOccluder) {
  const Scene scene = BoxScene();
  const SourceView left = test::RenderView(scene, CameraAt(BoxCamera(), {-0.6, 0, 0}), "left");
  const PosedCamera target = CameraAt(BoxCamera(), {0, 0.05, 0});
  const RenderResult result = Render({&left}, target, Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  const std::vector<Eigen::Vector3d> points = UnseenPoints(result, target);
  ASSERT_GT(points.size(), 500u);
  for (const Eigen::Vector3d& point : points) ASSERT_NEAR(point.z(), 8, 0.1);  // The wall.
  const Eigen::Quaterniond away(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()));
  const std::vector<PosedCamera> candidates = {CameraAt(BoxCamera(), {-1.2, 0, 0}),
                                               CameraAt(BoxCamera(), {0, 0, 0}, away),
                                               CameraAt(BoxCamera(), {0.6, 0, 0})};
  const SourceSelectionOptions options;
  EXPECT_EQ(SourceSeeingMost(candidates, target, points, {}, 32, options), 2);
  // Without it, the one further left still has the points in its frame (it is occluded too,
  // which is not known before it is loaded); the one looking away never does.
  EXPECT_EQ(SourceSeeingMost(candidates, target, points, {2}, 32, options), 0);
  EXPECT_EQ(SourceSeeingMost(candidates, target, points, {0, 2}, 32, options), -1);
}

// A target moved right of its only source sees a strip of the wall past the source's frame:
// out of view, and the fill continues the wall into it. Those pixels are unseen, their points
// lie on the wall, and a camera further right sees them where one to the left does not.
TEST(SourceSeeingMost, PicksTheViewThatSeesPastTheSourcesFrame) {
  const Camera camera = MakePinholeCamera(1, 320, 240, 300, 300, 160, 120);
  Scene scene;
  scene.planes.push_back(test::WallAt(5, test::WavyTexture({0.45f, 0.4f, 0.35f}, 0.4)));
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  // 30 px of disparity: the right 30 columns are out of the source's view.
  const PosedCamera target = CameraAt(camera, {0.5, 0, 0});
  const RenderResult result = Render({&source}, target, Options(WarpMethod::kMesh, FillMethod::kDepthAware));
  EXPECT_EQ(result.metrics.hole_ratio, 0);
  for (int y = 0; y < 240; y += 10) {
    EXPECT_TRUE(Unseen(result, 315, y)) << y;
    EXPECT_FALSE(Unseen(result, 280, y)) << y;
  }
  const std::vector<Eigen::Vector3d> points = UnseenPoints(result, target);
  EXPECT_NEAR(static_cast<double>(points.size()), 15 * 120, 2 * 120);  // Every other pixel.
  for (const Eigen::Vector3d& point : points) ASSERT_NEAR(point.z(), 5, 0.01);
  const std::vector<PosedCamera> candidates = {CameraAt(camera, {-0.5, 0, 0}),
                                               CameraAt(camera, {1.0, 0, 0})};
  EXPECT_EQ(SourceSeeingMost(candidates, target, points, {}, 32, {}), 1);
  EXPECT_EQ(SourceSeeingMost(candidates, target, points, {1}, 32, {}), -1);
}

// A target below the source and tilted up sees sky above the source's frame. At finite depth
// its top rays pass inside the source's frustum, where the source saw sky (empty space): no
// source saw anything there, so those pixels are out of view, not holes.
TEST(Render, TargetLookingAboveTheSourcesSkyIsOutOfViewNotAHole) {
  const Camera camera = MakePinholeCamera(1, 320, 240, 300, 300, 160, 120);
  Scene scene;
  // Ground 1.5 below the cameras (y points down), seen to 60 m; sky brighter upwards.
  scene.planes.push_back({Eigen::Vector3d::UnitY(), 1.5, test::WavyTexture({0.4f, 0.35f, 0.3f}, 0.7)});
  scene.boxes.push_back({{-1, -0.5, 6}, {1, 1.5, 7}, test::WavyTexture({0.6f, 0.3f, 0.2f}, 0.4)});
  scene.sky = [](const Eigen::Vector3d& dir) {
    const float k = static_cast<float>(0.6 - 0.4 * dir.y());
    return Eigen::Vector3f(0.3f * k, 0.5f * k, 0.9f * k);
  };
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  const double tilt = 15 * std::numbers::pi / 180;
  const PosedCamera target{camera, LookAt({0.3, 0.4, 0}, {0.3, 0.4 - 10 * std::tan(tilt), 10},
                                          {0, -1, 0})};
  // The frustum test alone (the former classification) calls the top rows holes.
  RenderOptions options = Options(WarpMethod::kMesh);
  const RenderResult result = Render({&source}, target, options);
  const BlendResult blend = [&] {
    WarpBuffer buffer;
    ForwardWarp(source, target, options.warp, &buffer);
    std::vector<WarpBuffer> buffers;
    buffers.push_back(std::move(buffer));
    BlendResult blended;
    Blend(buffers, options.blend, &blended);
    return blended;
  }();
  const ClassMap frustum_only = ClassifyPixels(blend, {source.Posed()}, target, options.holes);
  const HoleMetrics frustum_metrics = ComputeHoleMetrics(frustum_only);
  EXPECT_TRUE(frustum_only.open_to_sky.empty());  // Without depth maps it is not known.
  EXPECT_GT(frustum_metrics.hole_ratio, 0.05);
  // What is left is the ground the box hides (measured 1.1%).
  EXPECT_LT(result.metrics.hole_ratio, 0.02);
  EXPECT_LT(result.metrics.hole_ratio, 0.25 * frustum_metrics.hole_ratio);
  EXPECT_GT(result.metrics.out_of_view_ratio, 0.05);
  EXPECT_GT(result.metrics.background_ratio, 0.05);
  for (int x = 0; x < 320; x += 8) EXPECT_EQ(result.classes.At(x, 0), PixelClass::kOutOfView) << x;
  // The disocclusion beside the box stays a hole.
  const RenderResult sideways = Render({&source}, CameraAt(camera, {0.8, 0, 0}), options);
  EXPECT_GT(sideways.metrics.disocclusion_ratio, 0.005);
}

void ExpectFinite(const RenderResult& result) {
  for (float v : result.color.Pixels()) ASSERT_TRUE(std::isfinite(v));
  for (float z : result.depth.Values()) ASSERT_TRUE(std::isfinite(z) && z >= 0) << z;
  const HoleMetrics& m = result.metrics;
  for (double ratio : {m.covered_ratio, m.background_ratio, m.out_of_view_ratio, m.crack_ratio,
                       m.disocclusion_ratio, m.hole_ratio, result.fill.hole_ratio_filled}) {
    ASSERT_TRUE(ratio >= 0 && ratio <= 1) << ratio;
  }
  EXPECT_NEAR(m.covered_ratio + m.background_ratio + m.out_of_view_ratio + m.hole_ratio, 1, 1e-9);
}

void RenderAllWays(const std::vector<const SourceView*>& sources, const PosedCamera& target) {
  for (WarpMethod method : kMethods) {
    for (FillMethod fill : {FillMethod::kNone, FillMethod::kInpaint, FillMethod::kDepthAware}) {
      SCOPED_TRACE(std::string(Name(method)) + " fill " + std::to_string(static_cast<int>(fill)));
      ExpectFinite(Render(sources, target, Options(method, fill)));
    }
  }
}

// A class map whose size is no multiple of the counter's blocks (16 pixels, 4080 pixels) and
// whose classes run through every value: every pixel is counted once, under its class.
TEST(ClassCount, CountsEveryPixelOnceUnderItsClass) {
  ClassMap map{101, 97, {}, {}};
  std::array<size_t, kPixelClasses> expected{};
  for (int i = 0; i < map.width * map.height; ++i) {
    // Runs of varying length, so that blocks and vectors start mid-run.
    const auto c = static_cast<size_t>((i / 7 + i / 31) % 5);
    map.classes.push_back(static_cast<PixelClass>(c));
    ++expected[c];
  }
  EXPECT_EQ(CountClasses(map).pixels, expected);
  // One class everywhere: more matches per counter than a byte holds.
  map.classes.assign(map.classes.size(), PixelClass::kDisocclusion);
  const ClassCounts all = CountClasses(map);
  EXPECT_EQ(all[PixelClass::kDisocclusion], map.classes.size());
  EXPECT_EQ(all[PixelClass::kCovered] + all[PixelClass::kBackground] +
                all[PixelClass::kOutOfView] + all[PixelClass::kCrack],
            0u);
}

TEST(Render, TargetInsideTheSceneStaysFinite) {
  const Scene scene = BoxScene();
  const SourceView source = test::RenderView(scene, CameraAt(BoxCamera(), {0, 0, 0}));
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()));
  RenderAllWays({&source}, CameraAt(BoxCamera(), {0, 0, 6}, turn));  // Between box and wall.
  RenderAllWays({&source}, CameraAt(BoxCamera(), {0.2, 0.1, 4.5}));  // Inside the box.
  RenderAllWays({&source}, CameraAt(BoxCamera(), {0, 0, 9}));        // Behind the wall.
}

TEST(Render, SourcePixelOnTheTargetCameraPlaneStaysFinite) {
  // Odd size with the principal point on a pixel centre: column 10 looks along x = 0, row 7
  // along y = 0, so their points on the plane z = 5 lie in the target's camera plane x = 0
  // and one of them is the target centre itself.
  const Camera camera = MakePinholeCamera(1, 21, 15, 20, 20, 10.5, 7.5);
  Scene scene;
  scene.planes.push_back(test::WallAt(5, test::WavyTexture({0.5f, 0.5f, 0.5f}, 0.5)));
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  ASSERT_EQ(source.depth.At(10, 7), 5.0f);
  const PosedCamera target{camera, LookAt({0, 0, 5}, {1, 0, 5}, {0, 0, 1})};
  RenderAllWays({&source}, target);
  const PosedCamera grazing{camera, LookAt({0, 0, 5}, {1, 0, 5.001}, {0, 0, 1})};
  RenderAllWays({&source}, grazing);
}

TEST(Render, ExtremeDepthsStayFinite) {
  const Camera camera = MakePinholeCamera(1, 32, 24, 30, 30, 16, 12);
  const PosedCamera origin = CameraAt(camera, {0, 0, 0});
  for (float depth : {1e-6f, 1e6f}) {
    SourceView source = test::RenderView(Scene{}, origin);
    for (float& z : source.depth.Values()) z = depth;
    RenderAllWays({&source}, CameraAt(camera, {0.1, 0, 0}));
    RenderAllWays({&source}, CameraAt(camera, {0, 0, 1e-6}));
  }
  // A checkerboard of depths 1e-3 and 1e3: a discontinuity of 1e6 between every pair.
  SourceView checker = test::RenderView(Scene{}, origin);
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 32; ++x) checker.depth.At(x, y) = (x + y) % 2 == 0 ? 1e-3f : 1e3f;
  }
  RenderAllWays({&checker}, CameraAt(camera, {0.01, 0, 0}));
}

TEST(Render, OnePixelImagesStayFinite) {
  const Camera camera = MakePinholeCamera(1, 1, 1, 1, 1, 0.5, 0.5);
  Scene scene;
  scene.planes.push_back(test::WallAt(3, test::WavyTexture({0.5f, 0.5f, 0.5f}, 0.5)));
  const SourceView source = test::RenderView(scene, CameraAt(camera, {0, 0, 0}));
  RenderAllWays({&source}, CameraAt(camera, {0, 0, 0}));
  RenderAllWays({&source}, CameraAt(camera, {5, 0, 0}));
  const RenderResult same = Render({&source}, CameraAt(camera, {0, 0, 0}), Options(WarpMethod::kMesh));
  EXPECT_EQ(same.classes.At(0, 0), PixelClass::kCovered);
}

TEST(Render, RejectsBadInput) {
  const Scene scene = BoxScene();
  const SourceView source = test::RenderView(scene, CameraAt(BoxCamera(), {0, 0, 0}));
  const PosedCamera target = CameraAt(BoxCamera(), {0, 0, 0});
  EXPECT_THROW(Render({}, target), InternalError);
  EXPECT_THROW(Render({nullptr}, target), InternalError);
  RenderOptions options;
  options.holes.crack_opening_px = 2;
  EXPECT_THROW(Render({&source}, target, options), UsageError);
  PosedCamera distorted = target;
  distorted.camera = Camera{1, CameraModel::kOpenCV, 400, 300, {400, 400, 200, 150, 0.1, 0, 0, 0}};
  EXPECT_THROW(Render({&source}, distorted), InternalError);
}

}  // namespace
}  // namespace parallax

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "apps/viewer_paths.h"
#include "core/error.h"
#include "core/sparse_model.h"
#include "tests/temp_dir.h"
#include "testing/viewer_scenes.h"
#include "geometry/robust_bounds.h"
#include "tests/test_paths.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {
using namespace viewer_test;
namespace fs = std::filesystem;

const fs::path kSmall = SourceDir() / "example_images" / "small";

// The small example scene as the viewer sees a workspace: its own geometry as the mesh, its
// ground-truth cameras and photos as the sources.
ViewerScene SmallScene() {
  const SceneDesc desc = ReadSceneJson(kSmall / "scene.json");
  ViewerScene scene = SceneFromObjects(desc.objects);
  const SparseModel model = ReadSparseModel(kSmall / "gt" / "sparse");
  for (const SparseImage& image : model.Images()) {
    scene.sources.push_back({image.name, model.CameraById(image.camera_id), image.cam_from_world,
                             kSmall / "images" / image.name});
  }
  FinishViewerScene(scene);
  return scene;
}

TEST(ViewerProjective, ScreenshotFromASourceCameraReproducesItsPhoto) {
  EnsureGlContext();
  const ViewerScene scene = SmallScene();
  ASSERT_TRUE(scene.ground.has_value());
  EXPECT_GT(scene.ground->normal.z(), 0.999) << "the ground of a z-up scene is horizontal";
  SceneRenderer renderer(scene);
  FrameSettings settings;
  settings.texture = TextureMode::kProjective;
  settings.shadows = ShadowMode::kNone;
  settings.show_cameras = false;
  settings.show_grid = false;
  for (const std::string name : {"0000", "0005.png"}) {
    const ViewCamera view = SourceViewCamera(scene, name);
    const FrameResult result = renderer.Render(view, settings);
    const Image photo = ReadImage(kSmall / "images" / (std::filesystem::path(name).stem().string() + ".png"));
    if (const char* dir = std::getenv("PARALLAX_VIEWER_TEST_OUT")) {
      fs::create_directories(dir);
      WriteImage(fs::path(dir) / ("projective_" + name + ".png"), result.color, PixelFormat::kUint8);
    }
    ASSERT_EQ(photo.Width(), result.color.Width());
    double squared = 0;
    int covered = 0;
    for (int y = 0; y < photo.Height(); ++y) {
      for (int x = 0; x < photo.Width(); ++x) {
        if (!RenderedCovered(result.aux, x, y)) continue;
        ++covered;
        for (int c = 0; c < 3; ++c) {
          const double d = static_cast<double>(result.color.At(x, y, c) - photo.At(x, y, c));
          squared += d * d;
        }
      }
    }
    const double psnr = 10 * std::log10(1.0 / (squared / (3.0 * covered)));
    std::printf("[ measure ] projective texturing from %s: PSNR %.2f dB over %d covered pixels\n", name.c_str(),
                psnr, covered);
    EXPECT_GT(covered, photo.Width() * photo.Height() / 2);
    EXPECT_GE(psnr, 25);
  }
}

// The mean red share r / (r + g + b) of the covered pixels.
double MeanRedShare(const FrameResult& frame) {
  double sum = 0;
  int covered = 0;
  for (int y = 0; y < frame.color.Height(); ++y) {
    for (int x = 0; x < frame.color.Width(); ++x) {
      if (!RenderedCovered(frame.aux, x, y)) continue;
      const double total = frame.color.At(x, y, 0) + frame.color.At(x, y, 1) + frame.color.At(x, y, 2);
      sum += total > 0 ? static_cast<double>(frame.color.At(x, y, 0)) / total : 0;
      ++covered;
    }
  }
  return covered > 0 ? sum / covered : 0;
}

TEST(ViewerLevelOfDetail, DisplayMeshIsDrawnWhenThePixelsCannotShowEveryTriangle) {
  EnsureGlContext();
  ViewerScene scene = SmallScene();
  // The same geometry with a red atlas stands in for the simplified copy: the color tells
  // which level was drawn.
  scene.display_mesh = scene.mesh;
  scene.display_mesh.atlas = Image(2, 2, 3);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 2; ++x) scene.display_mesh.atlas.At(x, y, 0) = 0.9f;
  }
  SceneRenderer renderer(scene);
  FrameSettings settings;
  settings.shadows = ShadowMode::kPcf;
  settings.show_cameras = false;
  settings.show_grid = false;
  ViewCamera view = OrbitViewCamera(scene, 30, std::nullopt, 64, 48);
  // 16 pixels a triangle: the full mesh fits a view of this many pixels and more.
  const size_t fits = scene.mesh.triangles.size() * 16;
  ASSERT_LT(64u * 48u, fits) << "the small frame must be too small for the full mesh";
  EXPECT_GT(MeanRedShare(renderer.Render(view, settings)), 0.8);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(fits)))) + 1;
  view = OrbitViewCamera(scene, 30, std::nullopt, side, side);
  EXPECT_LT(MeanRedShare(renderer.Render(view, settings)), 0.5);  // The full mesh is grey.
}

TEST(ViewerProjective, NearestSourceViewsAreThoseAroundTheEye) {
  const ViewerScene scene = SmallScene();
  const Eigen::Vector3d eye = CameraCenter(scene.sources[3].cam_from_world);
  const std::vector<int> nearest = NearestSourceViews(scene, eye, 3);
  ASSERT_EQ(nearest.size(), 3u);
  EXPECT_EQ(nearest[0], 3);
  for (int i : nearest) EXPECT_LE(std::abs(i - 3), 1);  // Views on an arc: the neighbours.
}

TEST(ViewerScene, EmptyWorkspaceIsBadInputNamingTheFolder) {
  const TempDir dir;
  try {
    LoadViewerScene(ViewerScenePathsFor(dir.Path()));
    FAIL() << "expected BadInputError";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find(dir.Path().string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("fused.ply"), std::string::npos) << error.what();
  }
}

TEST(ViewerScene, RobustBoundsIgnoreOnePercentOfFarOutliers) {
  std::mt19937 random(3);
  std::uniform_real_distribution<float> x(-5, 5), y(-3, 3), z(0, 2);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 9900; ++i) points.emplace_back(x(random), y(random), z(random));
  // 1%: half of them 1000 units away on one side, half on the other.
  for (int i = 0; i < 100; ++i) points.emplace_back((i % 2 ? 1000.0f : -700.0f) + x(random), -400, 900);
  const Eigen::AlignedBox3f box = RobustBounds(points);
  EXPECT_LT((box.min() - Eigen::Vector3f(-5, -3, 0)).norm(), 0.1f) << box.min().transpose();
  EXPECT_LT((box.max() - Eigen::Vector3f(5, 3, 2)).norm(), 0.1f) << box.max().transpose();
  EXPECT_TRUE(RobustBounds({}).isEmpty());
  const Eigen::AlignedBox3f exact = RobustBounds(points, 0);
  EXPECT_FLOAT_EQ(exact.max().z(), 900);
  EXPECT_THROW(RobustBounds(points, 0.5f), InternalError);
}

// A fused cloud of a 20 x 20 courtyard with a block on it, plus 0.5% of points strewn up to
// 40 scene sizes away: the extent, the grid and the framing follow the courtyard.
TEST(ViewerScene, FarOutliersOfTheCloudDoNotShrinkTheScene) {
  ViewerScene scene;
  std::mt19937 random(5);
  std::uniform_real_distribution<float> ground(-10, 10), block(-2, 2), height(0, 3), far(-800, 800);
  for (int i = 0; i < 40000; ++i) {
    ColoredPoint p{{ground(random), ground(random), 0}, {0, 0, 1}, {128, 128, 128}};
    if (i % 4 == 0) p.position = {block(random), block(random), height(random)};
    if (i % 200 == 0) p.position = {far(random), far(random), std::abs(far(random))};
    scene.points.push_back(p);
  }
  FinishViewerScene(scene);
  ASSERT_TRUE(scene.ground.has_value());
  EXPECT_GT(scene.bounds.diagonal().norm(), 500);
  EXPECT_LT((scene.extent.min() - Eigen::Vector3f(-10, -10, 0)).norm(), 0.5f) << scene.extent.min().transpose();
  EXPECT_LT((scene.extent.max() - Eigen::Vector3f(10, 10, 3)).norm(), 0.5f) << scene.extent.max().transpose();
  EXPECT_LT((scene.focus.max() - Eigen::Vector3f(2, 2, 3)).norm(), 0.5f) << scene.focus.max().transpose();
  // The orbit frames the block: its distance is a few block sizes, not hundreds of units.
  const ViewCamera view = OrbitViewCamera(scene, 30, 30, 640, 480, 50);
  const double distance = (CameraCenter(view.cam_from_world) - Eigen::Vector3d(0, 0, 1.5)).norm();
  EXPECT_GT(distance, 4);
  EXPECT_LT(distance, 20);
}

TEST(ViewerScene, OrbitLooksWhereTheSourceCamerasLookFromAsFar) {
  const ViewerScene scene = SmallScene();
  ASSERT_TRUE(scene.rig.has_value()) << "the small scene's cameras stand on an arc looking in";
  // Every camera of the arc is 5.46 from its centre of interest.
  for (const ViewerSource& source : scene.sources) {
    EXPECT_NEAR((CameraCenter(source.cam_from_world) - scene.rig->target).norm(), scene.rig->distance, 0.05);
  }
  // With the photos' own field of view, the default orbit at a camera's azimuth and elevation
  // stands where that camera stands.
  const ViewerSource& source = scene.sources[4];
  const Eigen::Vector3d offset = CameraCenter(source.cam_from_world) - scene.rig->target;
  const double azimuth_deg = std::atan2(offset.y(), offset.x()) * 180 / std::numbers::pi;
  const double fov_deg = 2 * std::atan(0.5 * static_cast<double>(source.camera.width) / source.camera.FocalX()) * 180 /
                         std::numbers::pi;
  const ViewCamera view = OrbitViewCamera(scene, azimuth_deg, std::nullopt, 320, 240, fov_deg);
  EXPECT_LT((CameraCenter(view.cam_from_world) - CameraCenter(source.cam_from_world)).norm(), 0.1);
  // Cameras all looking ahead, as on a walk, make no rig.
  std::vector<ViewerSource> walk;
  for (int i = 0; i < 10; ++i) {
    walk.push_back(scene.sources[0]);
    walk.back().cam_from_world = LookAt(Eigen::Vector3d(i, 0, 1), Eigen::Vector3d(i + 5, 0, 1), Eigen::Vector3d::UnitZ());
  }
  EXPECT_FALSE(FitCameraRig(FrameCameras(walk), Eigen::Vector3d::UnitZ(), scene.extent).has_value());
}

// Looking through a source camera: its own frustum and those next to it are not drawn, so the
// frame differs from one without cameras only where farther frusta show.
TEST(ViewerProjective, LookingThroughASourceCameraHidesItsFrustum) {
  EnsureGlContext();
  const ViewerScene scene = SmallScene();
  SceneRenderer renderer(scene);
  FrameSettings settings;
  settings.shadows = ShadowMode::kNone;
  settings.show_grid = false;
  const ViewCamera view = SourceViewCamera(scene, "0006");
  const FrameResult with = renderer.Render(view, settings);
  settings.show_cameras = false;
  const FrameResult without = renderer.Render(view, settings);
  int different = 0;
  for (int y = 0; y < with.color.Height(); ++y) {
    for (int x = 0; x < with.color.Width(); ++x) {
      different += (with.color.At(x, y, 0) != without.color.At(x, y, 0));
    }
  }
  std::printf("[ measure ] frusta seen from camera 0006: %d pixels\n", different);
  EXPECT_LT(different, with.color.Width() * with.color.Height() / 100);
}

TEST(ViewerScene, GroundPlaneIsFoundDespiteOutliers) {
  // 2000 points on a tilted plane with noise, 800 outliers above it.
  std::vector<Eigen::Vector3f> points;
  const Eigen::Vector3d normal = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  const Eigen::Vector3d u = normal.cross(Eigen::Vector3d::UnitX()).normalized(), v = normal.cross(u);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-5, 5);
  std::normal_distribution<double> noise(0, 0.005);
  for (int i = 0; i < 2000; ++i) {
    points.push_back((uniform(random) * u + uniform(random) * v + (2 + noise(random)) * normal).cast<float>());
  }
  for (int i = 0; i < 800; ++i) {
    points.push_back(Eigen::Vector3d(uniform(random), uniform(random), 3 + std::abs(uniform(random))).cast<float>());
  }
  const std::optional<GroundPlane> plane = FitGroundPlane(points, std::nullopt);
  ASSERT_TRUE(plane.has_value());
  EXPECT_GT(plane->normal.dot(normal), 0.99999);
  EXPECT_NEAR(plane->offset, -2, 0.005);
  EXPECT_GE(plane->inliers, 1950);
}

}  // namespace
}  // namespace parallax

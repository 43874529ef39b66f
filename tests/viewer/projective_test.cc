#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sparse_model.h"
#include "tests/temp_dir.h"
#include "tests/viewer/viewer_test_util.h"
#include "viewer/view_cameras.h"

namespace parallax {
namespace {
using namespace viewer_test;
namespace fs = std::filesystem;

const fs::path kSmall = fs::path(PARALLAX_SOURCE_DIR) / "example_images" / "small";

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
  Renderer renderer(scene);
  RenderSettings settings;
  settings.texture = TextureMode::kProjective;
  settings.shadows = ShadowMode::kNone;
  settings.show_cameras = false;
  settings.show_grid = false;
  for (const std::string name : {"0000", "0005.png"}) {
    const ViewCamera view = SourceViewCamera(scene, name);
    const RenderResult result = renderer.Render(view, settings);
    const Image photo = ReadImage(kSmall / "images" / (std::filesystem::path(name).stem().string() + ".png"));
    if (const char* dir = std::getenv("PARALLAX_VIEWER_TEST_OUT")) {
      fs::create_directories(dir);
      WriteImage(fs::path(dir) / ("projective_" + name + ".png"), result.colour, PixelFormat::kUint8);
    }
    ASSERT_EQ(photo.Width(), result.colour.Width());
    double squared = 0;
    int covered = 0;
    for (int y = 0; y < photo.Height(); ++y) {
      for (int x = 0; x < photo.Width(); ++x) {
        if (!RenderedCovered(result.aux, x, y)) continue;
        ++covered;
        for (int c = 0; c < 3; ++c) {
          const double d = static_cast<double>(result.colour.At(x, y, c) - photo.At(x, y, c));
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
    LoadViewerScene(dir.Path());
    FAIL() << "expected BadInputError";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find(dir.Path().string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("fused.ply"), std::string::npos) << error.what();
  }
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

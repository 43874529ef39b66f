#include "synth/ray_tracer.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "core/depth_map.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "synth/synth.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

const std::filesystem::path kSmallScene =
    SourceDir() / "example_images" / "small";

SceneDesc SmallScene() { return ReadSceneJson(kSmallScene / "scene.json"); }

TEST(RayTracer, GroundPlaneDepthMatchesTheAnalyticIntersection) {
  SceneDesc scene = SmallScene();
  scene.objects.resize(1);  // The ground plane z = 0 alone.
  const RayTracer tracer(scene);
  const Camera camera = SceneCamera(scene);
  const Rigid3d cam_from_world = LookAt({3, -4, 2.5}, {0.5, 0.5, 0}, Eigen::Vector3d::UnitZ());
  const RenderedView view = tracer.Render(camera, cam_from_world);
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3d eye = CameraCenter(cam_from_world);
  double worst = 0;
  int ground_pixels = 0;
  for (int y = 0; y < view.depth.Height(); ++y) {
    for (int x = 0; x < view.depth.Width(); ++x) {
      const Eigen::Vector3d ray = world_from_cam * *camera.Unproject({x + 0.5, y + 0.5});
      const double expected = ray.z() < 0 ? -eye.z() / ray.z() : 0;  // z-depth: ray has z_cam = 1.
      const double hit_x = eye.x() + expected * ray.x(), hit_y = eye.y() + expected * ray.y();
      if (expected > 0 && std::max(std::abs(hit_x), std::abs(hit_y)) > 19.9) continue;  // Plane edge.
      if (expected == 0) {
        EXPECT_EQ(view.depth.At(x, y), 0.0f);
        continue;
      }
      ++ground_pixels;
      worst = std::max(worst, std::abs(static_cast<double>(view.depth.At(x, y)) - expected) / expected);
    }
  }
  EXPECT_GT(ground_pixels, 40000);
  EXPECT_LT(worst, 2e-6);  // float32 ray tracing.
}

TEST(RayTracer, OutputDoesNotDependOnTheThreadCount) {
  SceneDesc scene = SmallScene();
  const RayTracer tracer(scene);
  const Camera camera = SceneCamera(scene);
  RenderedView one, two;
  tbb::task_arena(1).execute([&] { one = tracer.Render(camera, scene.novel[2].cam_from_world); });
  tbb::task_arena(2).execute([&] { two = tracer.Render(camera, scene.novel[2].cam_from_world); });
  EXPECT_EQ(one.color.Pixels(), two.color.Pixels());
  EXPECT_EQ(one.depth.Values(), two.depth.Values());
  EXPECT_EQ(one.normal.Pixels(), two.normal.Pixels());
}

// Inverse depth is affine in the image over a plane, so it interpolates exactly there.
std::optional<double> InterpolateDepth(const DepthMap& depth, const Eigen::Vector2d& pixel) {
  const double fx = pixel.x() - 0.5, fy = pixel.y() - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= depth.Width() || y0 + 1 >= depth.Height()) return std::nullopt;
  const double corners[4] = {depth.At(x0, y0), depth.At(x0 + 1, y0), depth.At(x0, y0 + 1),
                             depth.At(x0 + 1, y0 + 1)};
  const auto [low, high] = std::minmax_element(corners, corners + 4);
  if (*low <= 0 || *high > *low * 1.01) return std::nullopt;  // Hole or depth edge.
  const double ax = fx - x0, ay = fy - y0;
  const double inverse = (1 - ax) * (1 - ay) / corners[0] + ax * (1 - ay) / corners[1] +
                         (1 - ax) * ay / corners[2] + ax * ay / corners[3];
  return 1 / inverse;
}

TEST(RayTracer, GroundTruthDepthIsConsistentAcrossViews) {
  const SceneFolder folder{kSmallScene};
  const SparseModel model = ReadSparseModel(folder.Training().sparse);
  const Camera& camera = model.Cameras().front();
  const auto& images = model.Images();
  std::vector<double> errors;
  for (size_t i = 0; i < images.size(); ++i) {
    const SparseImage& a = images[i];
    const SparseImage& b = images[(i + 1) % images.size()];
    const DepthMap depth_a = ReadDepthExr(folder.Training().DepthFor(a.name));
    const DepthMap depth_b = ReadDepthExr(folder.Training().DepthFor(b.name));
    const Rigid3d b_from_a = RelativePose(a.cam_from_world, b.cam_from_world);
    for (int y = 0; y < depth_a.Height(); y += 2) {
      for (int x = 0; x < depth_a.Width(); x += 2) {
        const auto point_in_a = camera.Unproject({x + 0.5, y + 0.5}, depth_a.At(x, y));
        if (!point_in_a) continue;
        const Eigen::Vector3d point_in_b = b_from_a * *point_in_a;
        const auto pixel_in_b = camera.Project(point_in_b);
        if (!pixel_in_b) continue;
        const auto seen_by_b = InterpolateDepth(depth_b, *pixel_in_b);
        if (!seen_by_b || point_in_b.z() > *seen_by_b * 1.01) continue;  // Occluded in b.
        errors.push_back(std::abs(point_in_b.z() - *seen_by_b) / *seen_by_b);
      }
    }
  }
  ASSERT_GT(errors.size(), 50000u);
  std::sort(errors.begin(), errors.end());
  const double within = static_cast<double>(std::lower_bound(errors.begin(), errors.end(), 1e-3) -
                                            errors.begin()) / static_cast<double>(errors.size());
  EXPECT_LT(errors[errors.size() / 2], 1e-5);
  EXPECT_GT(within, 0.995);
}

}  // namespace
}  // namespace parallax

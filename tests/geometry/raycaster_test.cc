// Rays through a camera's pixels: through its lens distortion, each hit projects back onto the
// pixel centre it was cast from.
#include "geometry/raycaster.h"

#include <vector>

#include <gtest/gtest.h>

namespace parallax {
namespace {

// A SIMPLE_RADIAL camera looking down +z at a square of side 40 at z = 5.
TEST(MeshRaycaster, PixelRaysGoThroughTheLensDistortion) {
  const std::vector<Eigen::Vector3f> vertices = {{-20, -20, 5}, {20, -20, 5}, {20, 20, 5}, {-20, 20, 5}};
  const MeshRaycaster raycaster(vertices, {{0, 1, 2}, {0, 2, 3}});
  Camera camera;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 64;
  camera.height = 48;
  camera.params = {50, 33, 22, -0.05};  // f, cx, cy, k: barrel distortion, off-centre.
  const Rigid3d identity;
  const std::vector<RayHit> hits = raycaster.CastPixels(camera, identity);
  ASSERT_EQ(hits.size(), 64u * 48u);
  double worst_px = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      const RayHit& hit = hits[static_cast<size_t>(y) * 64 + x];
      ASSERT_GE(hit.triangle, 0) << x << "," << y;
      EXPECT_NEAR(hit.depth, 5.0, 1e-4);
      // The hit point from its triangle's barycentric weights, projected back.
      const Eigen::Vector3i corners = hit.triangle == 0 ? Eigen::Vector3i(0, 1, 2) : Eigen::Vector3i(0, 2, 3);
      const Eigen::Vector3f point = (1 - hit.u - hit.v) * vertices[corners[0]] + hit.u * vertices[corners[1]] +
                                    hit.v * vertices[corners[2]];
      const std::optional<Eigen::Vector2d> pixel = camera.Project(point.cast<double>());
      ASSERT_TRUE(pixel.has_value());
      worst_px = std::max(worst_px, (*pixel - Eigen::Vector2d(x + 0.5, y + 0.5)).norm());
    }
  }
  EXPECT_LT(worst_px, 1e-3);  // Float rays and hits: ~1e-5 px.
}

}  // namespace
}  // namespace parallax

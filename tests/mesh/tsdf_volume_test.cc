// The signed-distance volume against an analytic sphere: depth maps computed from cameras
// around it, fused and meshed, the surface on the sphere, closed, made of blocks near the
// surface only, the same every time; one depth map alone is not enough where two are asked.
#include "mesh/tsdf_volume.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/pose.h"

namespace parallax {
namespace {

const Eigen::Vector3d kCentre(0.3, -0.2, 0.1);
constexpr double kRadius = 1;

struct View {
  Camera camera;
  Rigid3d cam_from_world;
  DepthMap depth;
};

// The z-depth of the sphere at each pixel centre of a camera at `eye` looking at its centre.
View SphereView(const Eigen::Vector3d& eye) {
  View view;
  view.camera = MakePinholeCamera(1, 160, 120, 150, 150, 80, 60);
  const Eigen::Vector3d up = std::abs(eye.normalized().z()) > 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  view.cam_from_world = LookAt(kCentre + eye, kCentre, up);
  view.depth = DepthMap(160, 120);
  const Eigen::Vector3d centre = view.cam_from_world * kCentre;
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const Eigen::Vector3d ray = Eigen::Vector3d((x + 0.5 - 80) / 150, (y + 0.5 - 60) / 150, 1).normalized();
      const double along = ray.dot(centre), miss = along * along - centre.squaredNorm() + kRadius * kRadius;
      if (miss > 0) view.depth.At(x, y) = static_cast<float>((along - std::sqrt(miss)) * ray.z());
    }
  }
  return view;
}

// Fourteen cameras 3.5 away: along the axes and the cube's diagonals.
std::vector<View> ViewsAround() {
  std::vector<View> views;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {-1.0, 1.0}) views.push_back(SphereView(3.5 * sign * Eigen::Vector3d::Unit(axis)));
  }
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d direction(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
    views.push_back(SphereView(3.5 * direction.normalized()));
  }
  return views;
}

TriangleMesh FuseAndMesh(const std::vector<View>& views, const TsdfOptions& options, float min_weight,
                         size_t* blocks = nullptr) {
  TsdfVolume volume(options);
  for (const View& view : views) volume.Integrate(view.camera, view.cam_from_world, view.depth);
  if (blocks) *blocks = volume.Blocks();
  return volume.Mesh(min_weight);
}

// Every voxel a depth map wrote is kept (a minimum weight of 1): asked for two, the sphere has
// holes where the voxels 1-2 voxels inside are within the truncation of the one camera that
// faces them only (an oblique camera measures their distance along its axis, longer by 1 / cos
// of its angle to the surface): 345 open edges around the point facing a diagonal camera.
TEST(TsdfVolume, SphereSeenAllAroundIsFusedOntoItsSurface) {
  const std::vector<View> views = ViewsAround();
  const TsdfOptions options{.voxel_size = 0.04, .truncation = 0.12};
  size_t blocks = 0;
  const TriangleMesh mesh = FuseAndMesh(views, options, 1, &blocks);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  std::vector<double> distances;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    distances.push_back(std::abs((v.cast<double>() - kCentre).norm() - kRadius));
  }
  std::sort(distances.begin(), distances.end());
  const double median = distances[distances.size() / 2], worst = distances.back();
  // Euler characteristic and closedness: every edge in two triangles.
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  }
  const bool closed = std::all_of(edges.begin(), edges.end(), [](const auto& edge) { return edge.second == 2; });
  const int euler = static_cast<int>(mesh.vertices.size()) - static_cast<int>(edges.size()) +
                    static_cast<int>(mesh.triangles.size());
  std::printf("[ measure ] sphere from 14 depth maps: %zu triangles, %zu blocks; vertices %.4f voxels off (median), "
              "%.4f at most; Euler characteristic %d\n",
              mesh.triangles.size(), blocks, median / options.voxel_size, worst / options.voxel_size, euler);
  EXPECT_LT(median, 0.1 * options.voxel_size);
  EXPECT_LT(worst, 0.5 * options.voxel_size);
  EXPECT_TRUE(closed);
  EXPECT_EQ(euler, 2);
  // Blocks only where a depth map put the surface (270, measured): a shell around the sphere,
  // about half the box around it here; a larger scene with the same surface holds the same
  // blocks. The mesh is closed across the blocks' borders.
  const double block = TsdfVolume::kBlockSide * options.voxel_size;
  const double box_blocks = std::pow(2 * (kRadius + options.truncation) / block + 1, 3);
  EXPECT_LT(static_cast<double>(blocks), box_blocks);
  // The same maps, the same mesh.
  const TriangleMesh again = FuseAndMesh(views, options, 1);
  EXPECT_EQ(again.vertices, mesh.vertices);
  EXPECT_EQ(again.triangles, mesh.triangles);
}

// One depth map is one view's weight: asked for two, nothing is kept; asked for one, the cap
// that camera sees, open at its rim.
TEST(TsdfVolume, OneDepthMapIsNotTwo) {
  const std::vector<View> one = {SphereView(Eigen::Vector3d(0, 0, 3.5))};
  const TsdfOptions options{.voxel_size = 0.04, .truncation = 0.12};
  EXPECT_TRUE(FuseAndMesh(one, options, 2).triangles.empty());
  const TriangleMesh cap = FuseAndMesh(one, options, 1);
  EXPECT_GT(cap.triangles.size(), 300u);
  for (const Eigen::Vector3f& v : cap.vertices) EXPECT_GT(v.z(), kCentre.z() - 0.3);  // The near side only.
}

TEST(TsdfVolume, BadOptionsAndCamerasAreRefused) {
  EXPECT_THROW(TsdfVolume({.voxel_size = 0, .truncation = 0.1}), BadInputError);
  EXPECT_THROW(TsdfVolume({.voxel_size = 0.1, .truncation = 0.05}), BadInputError);
  TsdfVolume volume({.voxel_size = 0.04, .truncation = 0.12});
  const View view = SphereView(Eigen::Vector3d(0, 0, 3.5));
  Camera wrong_size = view.camera;
  wrong_size.width = 200;
  EXPECT_THROW(volume.Integrate(wrong_size, view.cam_from_world, view.depth), BadInputError);
}

}  // namespace
}  // namespace parallax

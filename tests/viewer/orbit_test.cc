// `parallax render --path orbit:N` and `parallax view --orbit` follow one circle: the scene
// frame of geometry/scene_frame.h, fitted to the same workspace files.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "apps/viewer_paths.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/pose.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "geometry/obj.h"
#include "geometry/scene_frame.h"
#include "reproject/novel_views.h"
#include "tests/temp_dir.h"
#include "viewer/view_cameras.h"
#include "viewer/viewer_scene.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;

constexpr int kWidth = 320, kHeight = 240;
constexpr double kFocal = 280;

using Placement = std::function<Rigid3d(int index)>;

// Writes <ws>/sparse (`count` cameras, PINHOLE kWidth x kHeight, placed by `placement`) and an
// empty <ws>/images.
void WriteCameras(const fs::path& ws, int count, const Placement& placement) {
  SparseModel model;
  model.AddCamera(MakePinholeCamera(1, kWidth, kHeight, kFocal, kFocal, 0.5 * kWidth, 0.5 * kHeight));
  for (int i = 0; i < count; ++i) {
    SparseImage image;
    image.id = static_cast<uint32_t>(i + 1);
    image.camera_id = 1;
    image.name = std::to_string(1000 + i) + ".png";
    image.cam_from_world = placement(i);
    model.AddImage(image);
  }
  WriteSparseModel(model, Workspace(ws).Sparse(), SparseFormat::kText);
  fs::create_directories(Workspace(ws).Images());
}

// Cameras on a circle of radius 6, 2.5 above the ground, looking at the box's centre.
Rigid3d RingCamera(int index) {
  const double angle = 2 * std::numbers::pi * index / 8 + 0.3;
  const Eigen::Vector3d eye(6 * std::cos(angle), 6 * std::sin(angle), 2.5);
  return LookAt(eye, Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ());
}

// Cameras on a 100-degree arc of the ring, as in front of a facade.
Rigid3d ArcCamera(int index) {
  const double angle = 0.3 + (100 * std::numbers::pi / 180) * index / 5;
  const Eigen::Vector3d eye(6 * std::cos(angle), 6 * std::sin(angle), 2.5);
  return LookAt(eye, Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ());
}

// Cameras walking along x, all looking ahead: no rig.
Rigid3d WalkCamera(int index) {
  const Eigen::Vector3d eye(-4 + index, -3, 1.5);
  return LookAt(eye, eye + Eigen::Vector3d(1, 0.2, 0), Eigen::Vector3d::UnitZ());
}

// A 10 m square of ground with a 1 m box standing in its middle, as mesh/ (grey atlas) and as
// a fused.ply of points on both.
void WriteGeometry(const fs::path& ws) {
  TriangleMesh mesh;
  mesh.vertices = {{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  for (int corner = 0; corner < 8; ++corner) {
    mesh.vertices.emplace_back(corner & 1 ? 0.5f : -0.5f, corner & 2 ? 0.5f : -0.5f, corner & 4 ? 1.0f : 0.0f);
  }
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& face : faces) {
    mesh.triangles.emplace_back(4 + face[0], 4 + face[1], 4 + face[2]);
    mesh.triangles.emplace_back(4 + face[0], 4 + face[2], 4 + face[3]);
  }
  mesh.corner_uvs.assign(3 * mesh.triangles.size(), Eigen::Vector2f(0.5f, 0.5f));
  mesh.atlas = Image(2, 2, 3);
  for (float& v : mesh.atlas.Pixels()) v = 0.7f;
  WriteTexturedMesh(Workspace(ws).MeshDir(), mesh);

  std::vector<Eigen::Vector3f> points;
  for (int y = 0; y <= 60; ++y) {
    for (int x = 0; x <= 60; ++x) points.emplace_back(-5 + x / 6.0f, -5 + y / 6.0f, 0);
  }
  for (int i = 0; i < 1500; ++i) {
    points.emplace_back(-0.5f + static_cast<float>(i % 15) / 14, 0.5f, static_cast<float>(i / 15) / 99);
  }
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(points.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const Eigen::Vector3f& p : points) ply.append(reinterpret_cast<const char*>(p.data()), 3 * sizeof(float));
  WriteFileAtomically(Workspace(ws).Fused(), ply);
}

// The 12 cameras `parallax render --path orbit:12` renders for `ws`.
std::vector<NamedCamera> RenderOrbit(const fs::path& ws) {
  const SourceLibrary library(SourcePathsFor(ws));
  return CamerasAlongPath(ParseCameraPath("orbit:12"), Workspace(ws).Geometry(), library.Cameras(), library.Names());
}

// Render's orbit frame k against `view --orbit 30k --size 320x240 --fov F`, F the photos'
// horizontal field of view.
void ExpectRenderOrbitIsViewOrbit(const fs::path& ws) {
  const std::vector<NamedCamera> render = RenderOrbit(ws);
  const ViewerScene scene = LoadViewerScene(ViewerScenePathsFor(ws));
  const double fov_deg = 2 * std::atan(0.5 * kWidth / kFocal) * 180 / std::numbers::pi;
  ASSERT_EQ(render.size(), 12u);
  for (int k = 0; k < 12; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const ViewCamera view = OrbitViewCamera(scene, 30 * k, std::nullopt, kWidth, kHeight, fov_deg);
    const Rigid3d& orbit = render[static_cast<size_t>(k)].camera.cam_from_world;
    EXPECT_LT((orbit.rotation.toRotationMatrix() - view.cam_from_world.rotation.toRotationMatrix()).norm(), 1e-9);
    EXPECT_LT((orbit.translation - view.cam_from_world.translation).norm(), 1e-9);
    EXPECT_EQ(render[static_cast<size_t>(k)].camera.camera.width, static_cast<uint64_t>(kWidth));
    EXPECT_EQ(render[static_cast<size_t>(k)].camera.camera.FocalX(), kFocal);
  }
}

TEST(Orbit, RenderOrbitIsTheViewOrbitAroundARig) {
  const TempDir dir;
  const fs::path ws = dir.Path() / "ws";
  WriteCameras(ws, 8, RingCamera);
  WriteGeometry(ws);
  ASSERT_TRUE(LoadViewerScene(ViewerScenePathsFor(ws)).rig.has_value()) << "the ring looks in at the box";
  ExpectRenderOrbitIsViewOrbit(ws);
}

TEST(Orbit, RenderOrbitIsTheViewOrbitAroundTheFocusWithoutARig) {
  const TempDir dir;
  const fs::path ws = dir.Path() / "ws";
  WriteCameras(ws, 8, WalkCamera);
  WriteGeometry(ws);
  ASSERT_FALSE(LoadViewerScene(ViewerScenePathsFor(ws)).rig.has_value()) << "cameras looking ahead make no rig";
  ExpectRenderOrbitIsViewOrbit(ws);
}

// Photos from an arc of the circle only: the orbit runs from one end of the arc to the other
// (beyond it, it would look where no photo did), still the view orbit at those azimuths.
TEST(Orbit, RenderOrbitKeepsToTheArcThePhotosWereTakenFrom) {
  const TempDir dir;
  const fs::path ws = dir.Path() / "ws";
  WriteCameras(ws, 6, ArcCamera);
  WriteGeometry(ws);
  const ViewerScene scene = LoadViewerScene(ViewerScenePathsFor(ws));
  ASSERT_TRUE(scene.rig.has_value());
  EXPECT_NEAR(scene.rig->arc_span_deg, 100, 0.01);  // The rig's target is a least-squares fit.
  const std::vector<NamedCamera> render = RenderOrbit(ws);
  const double fov_deg = 2 * std::atan(0.5 * kWidth / kFocal) * 180 / std::numbers::pi;
  for (int k = 0; k < 12; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const double azimuth = scene.rig->arc_start_deg + scene.rig->arc_span_deg * k / 11;
    const ViewCamera view = OrbitViewCamera(scene, azimuth, std::nullopt, kWidth, kHeight, fov_deg);
    const Rigid3d& orbit = render[static_cast<size_t>(k)].camera.cam_from_world;
    EXPECT_LT((orbit.translation - view.cam_from_world.translation).norm(), 1e-9);
    // Its centre stands within the photos' azimuths about the rig's target.
    const Eigen::Vector3d offset = CameraCenter(orbit) - scene.rig->target;
    const double degrees = std::atan2(offset.y(), offset.x()) * 180 / std::numbers::pi;
    EXPECT_GE(degrees, 0.3 * 180 / std::numbers::pi - 0.01);
    EXPECT_LE(degrees, 0.3 * 180 / std::numbers::pi + 100 + 0.01);
  }
}

// photos:N runs through the photo cameras in azimuth order (written here in another order),
// from the first to the last, evenly by length and close to the circle they stand on.
TEST(Orbit, PhotoTourRunsThroughThePhotoCameras) {
  const TempDir dir;
  const fs::path ws = dir.Path() / "ws";
  WriteCameras(ws, 6, [](int index) { return ArcCamera((index * 5) % 6); });
  WriteGeometry(ws);
  const SourceLibrary library(SourcePathsFor(ws));
  const std::vector<NamedCamera> tour =
      CamerasAlongPath(ParseCameraPath("photos:21"), Workspace(ws).Geometry(), library.Cameras(), library.Names());
  ASSERT_EQ(tour.size(), 21u);
  const auto centre = [&](size_t k) { return CameraCenter(tour[k].camera.cam_from_world); };
  EXPECT_LT((centre(0) - CameraCenter(ArcCamera(0))).norm(), 1e-9);
  EXPECT_LT((centre(20) - CameraCenter(ArcCamera(5))).norm(), 1e-9);
  EXPECT_LT(RotationAngleDeg(tour[20].camera.cam_from_world.rotation, ArcCamera(5).rotation), 1e-6);
  const Eigen::Vector3d ring_centre(0, 0, 2.5);
  double shortest = 1e9, longest = 0;
  for (size_t k = 0; k < tour.size(); ++k) {
    EXPECT_NEAR((centre(k) - ring_centre).norm(), 6, 0.06) << k;  // Within 1% of the circle.
    if (k == 0) continue;
    const double step = (centre(k) - centre(k - 1)).norm();
    shortest = std::min(shortest, step);
    longest = std::max(longest, step);
  }
  EXPECT_LT(longest, 1.1 * shortest);
  EXPECT_EQ(ParseCameraPath("photos:21").Spec(), "photos:21");
  EXPECT_THROW(ParseCameraPath("photos:"), BadInputError);
}

TEST(Orbit, AzimuthArcIsTheCircleLessItsWidestGap) {
  EXPECT_EQ(AzimuthArc({}), std::make_pair(0.0, 360.0));
  EXPECT_EQ(AzimuthArc({42}), std::make_pair(0.0, 360.0));
  const auto [start, span] = AzimuthArc({20, -10, 10, 370});
  EXPECT_NEAR(start, 350, 1e-9);
  EXPECT_NEAR(span, 30, 1e-9);
  EXPECT_NEAR(AzimuthArc({0, 90, 180, 270}).second, 270, 1e-9);
}

// A scene folder, or a workspace without mesh and cloud: the cameras alone make the frame, so
// the orbit runs through the ring of cameras, looking at the point they look at.
TEST(Orbit, CamerasAloneGiveTheRingTheyStandOn) {
  const TempDir dir;
  const fs::path ws = dir.Path() / "ws";
  WriteCameras(ws, 8, RingCamera);
  const std::vector<NamedCamera> render = RenderOrbit(ws);
  ASSERT_EQ(render.size(), 12u);
  const Eigen::Vector3d target(0, 0, 0.5);
  for (const NamedCamera& camera : render) {
    const Eigen::Vector3d eye = CameraCenter(camera.camera.cam_from_world);
    EXPECT_NEAR(eye.z(), 2.5, 1e-9);
    EXPECT_NEAR(eye.head<2>().norm(), 6, 1e-9);
    const Eigen::Vector3d target_in_cam = camera.camera.cam_from_world * target;
    EXPECT_NEAR(target_in_cam.head<2>().norm(), 0, 1e-9) << "looks at the target";
  }
  EXPECT_EQ(render[3].name, "orbit_0003");
}

}  // namespace
}  // namespace parallax

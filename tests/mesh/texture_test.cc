// Texturing a mesh from photos, its files, and the PLY mesh reader, on analytic inputs.
#include "mesh/texture.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_metrics.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "eval/mesh_evaluation.h"
#include "geometry/ply.h"
#include "geometry/obj.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// Linear color painted on the plane z = 5, smooth enough to be resampled.
Eigen::Vector3f Paint(double x, double y) {
  return Eigen::Vector3f(static_cast<float>(0.5 + 0.4 * std::sin(3 * x)),
                         static_cast<float>(0.5 + 0.4 * std::cos(2 * y)),
                         static_cast<float>(0.3 + 0.2 * std::sin(x + y)));
}

constexpr double kPlaneDepth = 5;

// A camera at the origin looking down +z at the painted plane, and its photo.
TextureView PlaneView() {
  TextureView view;
  view.camera = MakePinholeCamera(1, 96, 72, 80, 80, 48, 36);
  view.color = Image(96, 72, 3);
  for (int y = 0; y < 72; ++y) {
    for (int x = 0; x < 96; ++x) {
      const Eigen::Vector3f color =
          Paint((x + 0.5 - 48) / 80 * kPlaneDepth, (y + 0.5 - 36) / 80 * kPlaneDepth);
      for (int c = 0; c < 3; ++c) view.color.At(x, y, c) = color[c];
    }
  }
  return view;
}

// A grid of quads on the plane, wider than the view.
TriangleMesh PlaneMesh(int cells) {
  TriangleMesh mesh;
  const double half = 4;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      mesh.vertices.emplace_back(static_cast<float>(-half + 2 * half * i / cells),
                                 static_cast<float>(-half + 2 * half * j / cells),
                                 static_cast<float>(kPlaneDepth));
    }
  }
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      const int a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
      mesh.triangles.emplace_back(a, b, c);
      mesh.triangles.emplace_back(b, d, c);
    }
  }
  return mesh;
}

TEST(Texture, RenderOfTheTexturedMeshReproducesThePhoto) {
  const TextureView view = PlaneView();
  const TriangleMesh plane = PlaneMesh(40);
  TextureSummary summary;
  const TriangleMesh mesh = TextureMesh(plane.vertices, plane.triangles, {view}, {}, summary);
  // Triangles outside the view stay untextured; the ones inside are ~2.6 px large.
  EXPECT_GT(summary.untextured_triangles, 0u);
  EXPECT_LT(summary.untextured_triangles, plane.triangles.size());
  EXPECT_GE(summary.texels_per_edge, 2);
  // Two triangles to a cell of (t + 5) x (t + 2) texels, where a square of t + 2 held one.
  const double cell_pair = (summary.texels_per_edge + 5.0) * (summary.texels_per_edge + 2.0);
  const double texels = static_cast<double>(mesh.atlas.Width()) * mesh.atlas.Height();
  EXPECT_GE(texels, cell_pair * static_cast<double>(plane.triangles.size()) / 2);
  EXPECT_LT(texels, 1.05 * cell_pair * static_cast<double>(plane.triangles.size()) / 2);

  std::vector<uint8_t> covered;
  const MeshRaycaster raycaster(mesh.vertices, mesh.triangles);
  const Image render =
      RenderTexturedMesh(mesh, raycaster, view.camera, view.cam_from_world, covered);
  double squared = 0;
  int pixels = 0;
  for (int y = 0; y < 72; ++y) {
    for (int x = 0; x < 96; ++x) {
      ASSERT_TRUE(covered[static_cast<size_t>(y * 96 + x)]);
      for (int c = 0; c < 3; ++c) {
        const double d = render.At(x, y, c) - LinearToSrgb(view.color.At(x, y, c));
        squared += d * d;
      }
      ++pixels;
    }
  }
  const double psnr = -10 * std::log10(squared / (3.0 * pixels));
  EXPECT_GT(psnr, 35) << "a plane seen head-on is textured almost losslessly";
}

// Ground seen from 1.7 above it, the camera tilted 6 degrees down: at the image's centre the
// ray meets the ground 84 degrees off its normal (16 m away), farther up the image more.
TEST(Texture, GroundSeenAtGrazingAnglesTakesItsPhoto) {
  const double tilt = 6 * std::numbers::pi / 180, height = 1.7;
  const Eigen::Vector3d centre(0, 0, kPlaneDepth - height);
  Eigen::Matrix3d cam_from_world;
  cam_from_world.row(0) = Eigen::Vector3d(-1, 0, 0);
  cam_from_world.row(1) = Eigen::Vector3d(0, -std::sin(tilt), std::cos(tilt));
  cam_from_world.row(2) = Eigen::Vector3d(0, std::cos(tilt), std::sin(tilt));
  TextureView view;
  view.camera = MakePinholeCamera(1, 96, 72, 80, 80, 48, 36);
  view.cam_from_world = Rigid3d(Eigen::Quaterniond(cam_from_world), -(cam_from_world * centre));
  view.color = Image(96, 72, 3);
  for (int y = 0; y < 72; ++y) {
    for (int x = 0; x < 96; ++x) {
      const Eigen::Vector3d ray = cam_from_world.transpose() * Eigen::Vector3d((x + 0.5 - 48) / 80, (y + 0.5 - 36) / 80, 1);
      const double t = ray.z() > 0 ? height / ray.z() : 0;  // Above the horizon: no ground.
      const Eigen::Vector3f color = Paint(0.2 * (centre + t * ray).x(), 0.2 * (centre + t * ray).y());
      for (int c = 0; c < 3; ++c) view.color.At(x, y, c) = color[c];
    }
  }
  // The ground from 4 m to 40 m ahead, 10 m to either side.
  TriangleMesh ground;
  for (int j = 0; j <= 36; ++j) {
    for (int i = 0; i <= 20; ++i) {
      ground.vertices.emplace_back(static_cast<float>(i - 10), static_cast<float>(4 + j), static_cast<float>(kPlaneDepth));
    }
  }
  for (int j = 0; j < 36; ++j) {
    for (int i = 0; i < 20; ++i) {
      const int a = j * 21 + i, b = a + 1, c = a + 21, d = c + 1;
      ground.triangles.emplace_back(a, b, c);
      ground.triangles.emplace_back(b, d, c);
    }
  }
  TextureSummary summary;
  const TriangleMesh mesh = TextureMesh(ground.vertices, ground.triangles, {view}, {}, summary);
  std::vector<uint8_t> covered;
  const MeshRaycaster raycaster(mesh.vertices, mesh.triangles);
  const Image render = RenderTexturedMesh(mesh, raycaster, view.camera, view.cam_from_world, covered);
  Image photo = LinearToSrgb(view.color);
  const double psnr = Psnr(render, photo, covered);
  std::printf("[ measure ] ground at grazing angles: %zu of %zu triangles untextured, %.2f dB\n",
              summary.untextured_triangles, mesh.triangles.size(), psnr);
  EXPECT_GT(psnr, 25);
  // At 80 degrees, the old limit, the ground past 10 m went grey.
  TextureOptions strict;
  strict.max_view_angle_deg = 80;
  TextureSummary strict_summary;
  TextureMesh(ground.vertices, ground.triangles, {view}, strict, strict_summary);
  std::printf("[ measure ] at 80 degrees: %zu untextured\n", strict_summary.untextured_triangles);
  EXPECT_GT(strict_summary.untextured_triangles, summary.untextured_triangles + 300);
}

TEST(Texture, TexturedMeshFilesRoundTrip) {
  const TempDir dir;
  const TextureView view = PlaneView();
  const TriangleMesh plane = PlaneMesh(4);
  TextureSummary summary;
  const TriangleMesh mesh = TextureMesh(plane.vertices, plane.triangles, {view}, {}, summary);
  WriteTexturedMesh(Workspace(dir.Path()).MeshDir(), mesh);
  EXPECT_FALSE(std::filesystem::exists(dir.Path() / "mesh.tmp"));
  const TriangleMesh read = ReadTexturedMesh(Workspace(dir.Path()).Mesh());
  ASSERT_EQ(read.triangles.size(), mesh.triangles.size());
  ASSERT_EQ(read.corner_uvs.size(), mesh.corner_uvs.size());
  for (size_t i = 0; i < mesh.corner_uvs.size(); ++i) {
    EXPECT_LT((read.corner_uvs[i] - mesh.corner_uvs[i]).norm(), 1e-6f);
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    EXPECT_LT((read.vertices[i] - mesh.vertices[i]).norm(), 1e-5f);
  }
  EXPECT_EQ(read.atlas.Width(), mesh.atlas.Width());
  // The atlas went through 8-bit PNG.
  EXPECT_NEAR(read.atlas.At(3, 3, 1), mesh.atlas.At(3, 3, 1), 0.5f / 255 + 1e-6f);
}

TEST(Texture, MalformedObjNamesFileAndLine) {
  const TempDir dir;
  std::ofstream(dir.Path() / "bad.obj") << "mtllib m.mtl\nv 0 0 0\nvt 0 0\nf 1/1 2/1 1/1\n";
  try {
    ReadTexturedMesh(dir.Path() / "bad.obj");
    FAIL() << "no error";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find("bad.obj:4"), std::string::npos) << error.what();
  }
}

TEST(Ply, ReadsMeshesAndRejectsIndicesOutOfRange) {
  const TempDir dir;
  auto write = [&](int index) {
    std::ofstream file(dir.Path() / "m.ply", std::ios::binary);
    file << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
            "property float y\nproperty float z\nproperty uchar red\nelement face 1\n"
            "property list uchar int vertex_indices\nend_header\n";
    for (int v = 0; v < 3; ++v) {
      const float xyz[3] = {static_cast<float>(v), 1.0f, 2.0f};
      file.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
      file.put('\x7f');
    }
    file.put('\x03');
    const int indices[3] = {0, 1, index};
    file.write(reinterpret_cast<const char*>(indices), sizeof(indices));
  };
  write(2);
  const TriangleMesh mesh = ReadPly(dir.Path() / "m.ply");
  ASSERT_EQ(mesh.vertices.size(), 3u);
  ASSERT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(2, 1, 2));
  write(3);
  EXPECT_THROW(ReadPly(dir.Path() / "m.ply"), BadInputError);
  write(-1);
  EXPECT_THROW(ReadPly(dir.Path() / "m.ply"), BadInputError);
}

}  // namespace
}  // namespace parallax

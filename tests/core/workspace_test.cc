#include "core/workspace.h"

#include <gtest/gtest.h>

namespace parallax {
namespace {

TEST(Workspace, NamesEveryFileOfTheLayout) {
  const Workspace ws("/w");
  EXPECT_EQ(ws.Sparse(), "/w/sparse");
  EXPECT_EQ(ws.Image("sub/a.jpg"), "/w/images/sub/a.jpg");
  EXPECT_EQ(ws.Depth("sub/a.jpg"), "/w/depth/a.exr") << "depth maps are named by the photo's stem";
  EXPECT_EQ(ws.DepthConfidence("a.jpg"), "/w/depth/a.confidence.exr");
  EXPECT_EQ(ws.StereoDepthMap("a.jpg", StereoPass::kPhotometric),
            "/w/stereo/depth_maps/a.jpg.photometric.bin");
  EXPECT_EQ(ws.StereoNormalMap("a.jpg", StereoPass::kGeometric),
            "/w/stereo/normal_maps/a.jpg.geometric.bin");
  EXPECT_EQ(ws.Fused(), "/w/fused.ply");
  EXPECT_EQ(ws.Mesh(), "/w/mesh/mesh.obj");
  EXPECT_EQ(ws.DisplayMesh(), "/w/mesh_display/mesh.obj");
  EXPECT_EQ(ws.Database(), "/w/sfm/database.db");
  EXPECT_EQ(ws.Log("mapper"), "/w/logs/mapper.log");
}

}  // namespace
}  // namespace parallax

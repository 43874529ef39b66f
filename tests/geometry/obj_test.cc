#include "geometry/obj.h"

#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// An OBJ `body` after three vertices and texture coordinates, with its MTL and a 2x2 atlas.
std::filesystem::path WriteObj(const std::filesystem::path& dir, const std::string& body) {
  WriteImage(dir / "atlas.png", Image(2, 2, 3), PixelFormat::kUint8);
  WriteFileAtomically(dir / "m.mtl", "newmtl a\nmap_Kd atlas.png\n");
  const std::filesystem::path obj = dir / "m.obj";
  WriteFileAtomically(obj, "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                           "vt 0 0\nvt 1 0\nvt 0 1\n" + body);
  return obj;
}

std::string ReadError(const std::filesystem::path& obj) {
  try {
    ReadTexturedMesh(obj);
  } catch (const BadInputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(Obj, RelativeIndicesAndGroupsAreRead) {
  const TempDir dir;
  const TriangleMesh mesh = ReadTexturedMesh(WriteObj(dir.Path(), "o part\nf 1/1 2/2 3/3\ng other\nf -2/-3 -1/-2 -3/-1\n"));
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(2, 3, 1));
  ASSERT_EQ(mesh.corner_uvs.size(), 6u);
  EXPECT_EQ(mesh.corner_uvs[4], Eigen::Vector2f(1, 0));
  EXPECT_EQ(mesh.atlas.Width(), 2);
}

TEST(Obj, PolygonsAndCornersWithoutTextureNameTheirLine) {
  const TempDir dir;
  const std::string quad = ReadError(WriteObj(dir.Path(), "f 1/1 2/2 3/3\nf 1/1 2/2 4/3 3/1\n"));
  EXPECT_NE(quad.find("m.obj:10: only triangles"), std::string::npos) << quad;
  const std::string bare = ReadError(WriteObj(dir.Path(), "f 1 2 3\n"));
  EXPECT_NE(bare.find("m.obj:9:"), std::string::npos) << bare;
  const std::string zero = ReadError(WriteObj(dir.Path(), "f 0/1 1/1 2/1\n"));
  EXPECT_NE(zero.find("m.obj"), std::string::npos) << zero;
}

TEST(Obj, AMissingMtllibOrTextureIsNamed) {
  const TempDir dir;
  WriteFileAtomically(dir.Path() / "bare.obj", "v 0 0 0\n");
  EXPECT_NE(ReadError(dir.Path() / "bare.obj").find("bare.obj: no mtllib"), std::string::npos);
  const std::filesystem::path obj = WriteObj(dir.Path(), "f 1/1 2/2 3/3\n");
  WriteFileAtomically(dir.Path() / "m.mtl", "newmtl a\n");
  EXPECT_NE(ReadError(obj).find("no map_Kd"), std::string::npos) << ReadError(obj);
}

}  // namespace
}  // namespace parallax

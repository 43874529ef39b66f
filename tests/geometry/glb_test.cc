// The binary glTF export (geometry/glb.h): its layout read back byte by byte, and the file
// checked by the Khronos glTF-Validator and opened by assimp, as a user's tools would.
#include "geometry/glb.h"

#include <cstdint>
#include <cstring>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "geometry/obj.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

// Two triangles of a unit square in z = 2, each with its own corner coordinates, and a 4x2
// atlas.
TriangleMesh Square() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.corner_uvs = {{0, 0}, {0.5f, 0}, {0.5f, 1}, {0.5f, 0}, {1, 1}, {1, 0.25f}};
  mesh.atlas = Image(4, 2, 3);
  for (int x = 0; x < 4; ++x) mesh.atlas.At(x, 0, 0) = 0.25f * static_cast<float>(x);
  return mesh;
}

uint32_t U32(const std::string& bytes, size_t offset) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, sizeof(value));
  return value;
}

float F32(const std::string& bytes, size_t offset) {
  float value = 0;
  std::memcpy(&value, bytes.data() + offset, sizeof(value));
  return value;
}

TEST(Glb, LayoutHoldsEveryCornerItsCoordinatesAndTheAtlas) {
  const TempDir dir;
  const TriangleMesh mesh = Square();
  WriteTexturedMesh(dir.Path() / "mesh", mesh);
  const std::string glb = ReadFileBytes(dir.Path() / "mesh" / "mesh.glb");
  const std::string png = ReadFileBytes(dir.Path() / "mesh" / "mesh.png");
  ASSERT_GE(glb.size(), 28u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  EXPECT_EQ(U32(glb, 4), 2u);
  EXPECT_EQ(U32(glb, 8), glb.size());
  const uint32_t json_size = U32(glb, 12);
  EXPECT_EQ(json_size % 4, 0u);
  EXPECT_EQ(glb.substr(16, 4), "JSON");
  const nlohmann::json document = nlohmann::json::parse(glb.substr(20, json_size));
  const size_t bin = 20 + json_size;
  EXPECT_EQ(glb.substr(bin + 4, 4), std::string("BIN\0", 4));
  const size_t data = bin + 8;
  EXPECT_EQ(U32(glb, bin) % 4, 0u);
  EXPECT_EQ(data + U32(glb, bin), glb.size());

  const auto& accessors = document["accessors"];
  EXPECT_EQ(accessors[0]["count"], 6);
  EXPECT_EQ(accessors[0]["min"], nlohmann::json({0, 0, 2}));
  EXPECT_EQ(accessors[0]["max"], nlohmann::json({1, 1, 2}));
  // The second triangle's corners: vertices 0, 2, 3.
  EXPECT_EQ(F32(glb, data + 12 * 5 + 4), 1.0f);   // Vertex 3's y.
  EXPECT_EQ(F32(glb, data + 12 * 4 + 0), 1.0f);   // Vertex 2's x.
  // Texture coordinates follow, v flipped to glTF's (0 at the atlas's top).
  const size_t uvs = data + 12 * 6;
  EXPECT_EQ(document["bufferViews"][1]["byteOffset"], 12 * 6);
  EXPECT_EQ(F32(glb, uvs + 8 * 5), 1.0f);
  EXPECT_EQ(F32(glb, uvs + 8 * 5 + 4), 0.75f);
  EXPECT_EQ(F32(glb, uvs + 8 * 0 + 4), 1.0f);
  // The atlas: the PNG file's bytes as they are.
  const auto& image_view = document["bufferViews"][document["images"][0]["bufferView"].get<int>()];
  EXPECT_EQ(glb.substr(data + image_view["byteOffset"].get<size_t>(), image_view["byteLength"].get<size_t>()), png);
  EXPECT_EQ(document["materials"][0]["extensions"].count("KHR_materials_unlit"), 1u);
}

TEST(Glb, MeshesItCannotHoldAreRefused) {
  const TempDir dir;
  TriangleMesh mesh = Square();
  mesh.corner_uvs.pop_back();
  EXPECT_THROW(WriteGlb(dir.Path() / "a.glb", mesh, ""), InternalError);
  mesh = Square();
  mesh.vertices[3].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(WriteGlb(dir.Path() / "a.glb", mesh, ""), InternalError);
  mesh = Square();
  mesh.triangles[1][2] = 4;
  EXPECT_THROW(WriteGlb(dir.Path() / "a.glb", mesh, ""), InternalError);
  EXPECT_THROW(WriteGlb(dir.Path() / "a.glb", TriangleMesh(), ""), InternalError);
  EXPECT_FALSE(std::filesystem::exists(dir.Path() / "a.glb"));
}

// What a user's tools say: the Khronos validator finds no error (and counts the triangles),
// assimp opens it with as many faces.
TEST(Glb, TheKhronosValidatorAndAssimpAcceptIt) {
  const TempDir dir;
  WriteTexturedMesh(dir.Path() / "mesh", Square());
  const std::string glb = (dir.Path() / "mesh" / "mesh.glb").string();
  const CliResult validator = RunCommand(Quote((SourceDir() / "scripts" / "validate-glb").string()) + " " + Quote(glb));
  ASSERT_EQ(validator.exit_code, 0) << validator.output;
  const nlohmann::json report = nlohmann::json::parse(validator.output);
  EXPECT_EQ(report["errors"], 0) << validator.output;
  EXPECT_EQ(report["warnings"], 0) << validator.output;
  EXPECT_EQ(report["triangles"], 2) << validator.output;
  const CliResult assimp = RunCommand("assimp info " + Quote(glb));
  EXPECT_EQ(assimp.exit_code, 0) << assimp.output;
  const size_t faces = assimp.output.find("Faces:");
  ASSERT_NE(faces, std::string::npos) << assimp.output;
  EXPECT_EQ(std::stoi(assimp.output.substr(faces + 6)), 2) << assimp.output;
}

}  // namespace
}  // namespace parallax

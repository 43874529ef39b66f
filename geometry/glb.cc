#include "geometry/glb.h"

#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {
namespace {

// glTF's constants (the specification's numeric enums).
constexpr int kFloat = 5126;
constexpr int kArrayBuffer = 34962;
constexpr int kTriangles = 4;
constexpr int kLinear = 9729;
constexpr int kClampToEdge = 33071;

void Append(std::string* bytes, const void* data, size_t size) {
  bytes->append(static_cast<const char*>(data), size);
}

void AppendU32(std::string* bytes, uint32_t value) { Append(bytes, &value, sizeof(value)); }

void Pad(std::string* bytes, char fill) {
  while (bytes->size() % 4 != 0) bytes->push_back(fill);
}

void CheckMesh(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) throw InternalError("WriteGlb: the mesh has no triangles");
  if (mesh.corner_uvs.size() != 3 * mesh.triangles.size()) {
    throw InternalError("WriteGlb: " + std::to_string(mesh.corner_uvs.size()) +
                        " texture coordinates for " + std::to_string(mesh.triangles.size()) +
                        " triangles, expected 3 per triangle");
  }
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      if (triangle[c] < 0 || static_cast<size_t>(triangle[c]) >= mesh.vertices.size()) {
        throw InternalError("WriteGlb: a triangle refers to vertex " + std::to_string(triangle[c]) +
                            " of " + std::to_string(mesh.vertices.size()));
      }
      if (!mesh.vertices[static_cast<size_t>(triangle[c])].allFinite()) {
        throw InternalError("WriteGlb: vertex " + std::to_string(triangle[c]) + " is not finite");
      }
    }
  }
}

nlohmann::json Document(size_t corners, const Eigen::Vector3f& low, const Eigen::Vector3f& high,
                        size_t png_size, size_t buffer_size) {
  const size_t positions = 12 * corners, uvs = 8 * corners;
  nlohmann::json unlit = nlohmann::json::object();
  return {
      {"asset", {{"version", "2.0"}, {"generator", "parallax"}}},
      {"extensionsUsed", {"KHR_materials_unlit"}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"rotation", {1, 0, 0, 0}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}},
                                    {"material", 0}, {"mode", kTriangles}}}}}}},
      {"materials", {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}},
                                                {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                      {"doubleSided", true},
                      {"extensions", {{"KHR_materials_unlit", unlit}}}}}},
      {"textures", {{{"sampler", 0}, {"source", 0}}}},
      // Linear without mipmaps: the atlas keeps neighbouring cells apart at full size only.
      {"samplers", {{{"magFilter", kLinear}, {"minFilter", kLinear},
                     {"wrapS", kClampToEdge}, {"wrapT", kClampToEdge}}}},
      {"images", {{{"bufferView", 2}, {"mimeType", "image/png"}}}},
      {"buffers", {{{"byteLength", buffer_size}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", positions}, {"target", kArrayBuffer}},
                       {{"buffer", 0}, {"byteOffset", positions}, {"byteLength", uvs}, {"target", kArrayBuffer}},
                       {{"buffer", 0}, {"byteOffset", positions + uvs}, {"byteLength", png_size}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", kFloat}, {"count", corners}, {"type", "VEC3"},
                      {"min", {low.x(), low.y(), low.z()}}, {"max", {high.x(), high.y(), high.z()}}},
                     {{"bufferView", 1}, {"componentType", kFloat}, {"count", corners}, {"type", "VEC2"}}}},
  };
}

}  // namespace

void WriteGlb(const std::filesystem::path& path, const TriangleMesh& mesh, std::string_view atlas_png) {
  CheckMesh(mesh);
  const size_t corners = 3 * mesh.triangles.size();
  std::string buffer;
  buffer.reserve(20 * corners + atlas_png.size() + 3);
  Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f high = -low;
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3f& v = mesh.vertices[static_cast<size_t>(triangle[c])];
      low = low.cwiseMin(v);
      high = high.cwiseMax(v);
      Append(&buffer, v.data(), 12);
    }
  }
  for (const Eigen::Vector2f& uv : mesh.corner_uvs) {
    // OBJ's v runs up from the atlas's bottom, glTF's down from its top.
    const float st[2] = {uv.x(), 1.0f - uv.y()};
    Append(&buffer, st, sizeof(st));
  }
  buffer.append(atlas_png);
  Pad(&buffer, '\0');

  std::string json = Document(corners, low, high, atlas_png.size(), buffer.size()).dump();
  Pad(&json, ' ');
  if (28 + json.size() + buffer.size() > std::numeric_limits<uint32_t>::max()) {
    throw InternalError("WriteGlb: " + std::to_string(mesh.triangles.size()) +
                        " triangles and the atlas exceed the 4 GiB a .glb can hold");
  }
  std::string glb;
  glb.reserve(28 + json.size() + buffer.size());
  AppendU32(&glb, 0x46546C67);  // "glTF"
  AppendU32(&glb, 2);
  AppendU32(&glb, static_cast<uint32_t>(28 + json.size() + buffer.size()));
  AppendU32(&glb, static_cast<uint32_t>(json.size()));
  AppendU32(&glb, 0x4E4F534A);  // "JSON"
  glb += json;
  AppendU32(&glb, static_cast<uint32_t>(buffer.size()));
  AppendU32(&glb, 0x004E4942);  // "BIN\0"
  glb += buffer;
  WriteFileAtomically(path, glb);
}

}  // namespace parallax

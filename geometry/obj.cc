#include "geometry/obj.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <tiny_obj_loader.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_sampling.h"
#include "core/interrupt.h"
#include "geometry/glb.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

std::string ObjText(const TriangleMesh& mesh) {
  std::string text = "# parallax textured mesh\nmtllib mesh.mtl\n";
  text.reserve(64 * (mesh.vertices.size() + 2 * mesh.corner_uvs.size()));
  char line[128];
  for (const Eigen::Vector3f& v : mesh.vertices) {
    std::snprintf(line, sizeof(line), "v %.7g %.7g %.7g\n", static_cast<double>(v.x()),
                  static_cast<double>(v.y()), static_cast<double>(v.z()));
    text += line;
  }
  for (const Eigen::Vector2f& uv : mesh.corner_uvs) {
    std::snprintf(line, sizeof(line), "vt %.7g %.7g\n", static_cast<double>(uv.x()),
                  static_cast<double>(uv.y()));
    text += line;
  }
  text += "usemtl atlas\n";
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const size_t uv = 3 * t + 1;  // OBJ indices count from 1.
    std::snprintf(line, sizeof(line), "f %d/%zu %d/%zu %d/%zu\n", tri[0] + 1, uv, tri[1] + 1,
                  uv + 1, tri[2] + 1, uv + 2);
    text += line;
  }
  return text;
}

[[noreturn]] void Malformed(const fs::path& path, size_t line_number, const std::string& what) {
  throw BadInputError(path.string() + ":" + std::to_string(line_number) + ": " + what);
}

// Where the OBJ's vertices, faces and first mtllib are (1-based line numbers), found in one
// pass: tinyobjloader keeps no line numbers, and the errors about vertices and faces name them.
struct ObjLines {
  std::vector<size_t> vertices;  // `v` lines, in order.
  std::vector<size_t> faces;     // `f` lines, in order.
  size_t mtllib = 0;             // 0: none.
  std::string mtllib_file;       // The file it names; empty when it names none.
};

ObjLines IndexLines(const std::string& text) {
  const auto is_blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  ObjLines lines;
  size_t number = 1;
  for (size_t start = 0; start < text.size(); ++number) {
    const size_t end = std::min(text.find('\n', start), text.size());
    size_t first = start;
    while (first < end && is_blank(text[first])) ++first;
    size_t last = first;
    while (last < end && !is_blank(text[last])) ++last;
    const std::string_view keyword(text.data() + first, last - first);
    const bool has_data = last < end;  // As tinyobjloader: a keyword alone on its line is no element.
    if (keyword == "v" && has_data) {
      lines.vertices.push_back(number);
    } else if (keyword == "f" && has_data) {
      lines.faces.push_back(number);
    } else if (keyword == "mtllib" && lines.mtllib == 0) {
      lines.mtllib = number;
      std::istringstream words(text.substr(last, end - last));
      words >> lines.mtllib_file;
    }
    start = end + 1;
  }
  return lines;
}

// The triangles and corner texture coordinates of `reader`'s shapes, checked against the
// vertices and coordinates it read. Throws BadInputError naming the face's line.
void CopyTriangles(const tinyobj::ObjReader& reader, const std::vector<size_t>& face_lines,
                   const fs::path& path, TriangleMesh& mesh) {
  const auto& texcoords = reader.GetAttrib().texcoords;
  const size_t num_uvs = texcoords.size() / 2;
  size_t face = 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t corner = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      const size_t line = face < face_lines.size() ? face_lines[face] : 0;
      if (corners != 3) Malformed(path, line, "only triangles are supported");
      Eigen::Vector3i triangle;
      for (int c = 0; c < 3; ++c, ++corner) {
        const tinyobj::index_t& index = shape.mesh.indices[corner];
        if (index.vertex_index < 0 || static_cast<size_t>(index.vertex_index) >= mesh.vertices.size() ||
            index.texcoord_index < 0 || static_cast<size_t>(index.texcoord_index) >= num_uvs) {
          Malformed(path, line, "a face corner refers to a missing vertex or texture coordinate");
        }
        triangle[c] = index.vertex_index;
        const size_t uv = 2 * static_cast<size_t>(index.texcoord_index);
        mesh.corner_uvs.emplace_back(texcoords[uv], texcoords[uv + 1]);
      }
      mesh.triangles.push_back(triangle);
      ++face;
    }
  }
}

}  // namespace

void WriteTexturedMesh(const fs::path& dir, const TriangleMesh& mesh) {
  const fs::path temporary = dir.string() + ".tmp";
  const TemporaryOutput guard(temporary);
  fs::remove_all(temporary);
  fs::create_directories(temporary);
  WriteFileAtomically(temporary / "mesh.obj", ObjText(mesh));
  WriteFileAtomically(temporary / "mesh.mtl",
                      "newmtl atlas\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd mesh.png\n");
  WriteImage(temporary / "mesh.png", mesh.atlas, PixelFormat::kUint8);
  WriteGlb(temporary / "mesh.glb", mesh, ReadFileBytes(temporary / "mesh.png"));
  fs::remove_all(dir);
  fs::rename(temporary, dir);
}

// The texture the MTL's first material names (map_Kd), beside the OBJ.
fs::path AtlasPath(const fs::path& mtl_path, const fs::path& obj_path) {
  std::istringstream mtl(ReadFileBytes(mtl_path));
  std::map<std::string, int> names;
  std::vector<tinyobj::material_t> materials;
  std::string warning, error;
  tinyobj::LoadMtl(&names, &materials, &mtl, &warning, &error);
  if (materials.empty() || materials.front().diffuse_texname.empty()) {
    throw BadInputError(mtl_path.string() + ": no map_Kd texture");
  }
  return obj_path.parent_path() / materials.front().diffuse_texname;
}

TriangleMesh ReadTexturedMesh(const fs::path& obj_path) {
  const std::string text = ReadFileBytes(obj_path);
  const ObjLines lines = IndexLines(text);
  if (lines.mtllib == 0) throw BadInputError(obj_path.string() + ": no mtllib");
  if (lines.mtllib_file.empty()) Malformed(obj_path, lines.mtllib, "mtllib names no file");
  const fs::path mtl_path = obj_path.parent_path() / lines.mtllib_file;
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // A polygon is an error, not split.
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", config)) {  // The material is read below.
    throw BadInputError(obj_path.string() + ": " + reader.Error());
  }
  TriangleMesh mesh;
  const std::vector<float>& vertices = reader.GetAttrib().vertices;
  for (size_t i = 0; i + 2 < vertices.size(); i += 3) {
    const Eigen::Vector3f v(vertices[i], vertices[i + 1], vertices[i + 2]);
    if (!v.allFinite()) Malformed(obj_path, i / 3 < lines.vertices.size() ? lines.vertices[i / 3] : 0, "bad vertex");
    mesh.vertices.push_back(v);
  }
  CopyTriangles(reader, lines.faces, obj_path, mesh);
  mesh.atlas = ReadImage(AtlasPath(mtl_path, obj_path));
  if (mesh.atlas.Channels() < 3) {
    throw BadInputError(obj_path.string() + ": the atlas must be an RGB image");
  }
  return mesh;
}

Eigen::Vector3f SampleAtlas(const Image& atlas, const Eigen::Vector2f& uv) {
  // v runs up, rows run down.
  return SampleBilinear(atlas, Eigen::Vector2f(uv.x() * static_cast<float>(atlas.Width()),
                                               (1.0f - uv.y()) * static_cast<float>(atlas.Height())));
}

}  // namespace parallax

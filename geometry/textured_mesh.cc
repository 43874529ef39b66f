#include "geometry/textured_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

std::string ObjText(const TexturedMesh& mesh) {
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

// One corner "v/vt" (or "v/vt/vn") of an OBJ face: zero-based indices, checked.
std::pair<int, int> ParseCorner(const std::string& word, const TexturedMesh& mesh,
                                size_t num_uvs, const fs::path& path, size_t line_number) {
  int v = 0, vt = 0;
  if (std::sscanf(word.c_str(), "%d/%d", &v, &vt) != 2) {
    Malformed(path, line_number, "face corner '" + word + "' is not v/vt");
  }
  if (v < 1 || static_cast<size_t>(v) > mesh.vertices.size() || vt < 1 ||
      static_cast<size_t>(vt) > num_uvs) {
    Malformed(path, line_number, "face corner '" + word + "' refers to a missing vertex");
  }
  return {v - 1, vt - 1};
}

fs::path AtlasPath(const fs::path& obj_path, const std::string& mtllib) {
  const fs::path mtl_path = obj_path.parent_path() / mtllib;
  std::istringstream mtl(ReadFileBytes(mtl_path));
  for (std::string line; std::getline(mtl, line);) {
    std::istringstream words(line);
    std::string keyword, file;
    words >> keyword >> file;
    if (keyword == "map_Kd" && !file.empty()) return obj_path.parent_path() / file;
  }
  throw BadInputError(mtl_path.string() + ": no map_Kd texture");
}

}  // namespace

void WriteTexturedMesh(const fs::path& dir, const TexturedMesh& mesh) {
  const fs::path temporary = dir.string() + ".tmp";
  fs::remove_all(temporary);
  fs::create_directories(temporary);
  WriteFileAtomically(temporary / "mesh.obj", ObjText(mesh));
  WriteFileAtomically(temporary / "mesh.mtl",
                      "newmtl atlas\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd mesh.png\n");
  WriteImage(temporary / "mesh.png", mesh.atlas, PixelFormat::kUint8);
  fs::remove_all(dir);
  fs::rename(temporary, dir);
}

TexturedMesh ReadTexturedMesh(const fs::path& obj_path) {
  std::istringstream lines(ReadFileBytes(obj_path));
  TexturedMesh mesh;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> uv_triangles;
  std::string mtllib;
  size_t line_number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") {
      Eigen::Vector3f v;
      if (!(words >> v.x() >> v.y() >> v.z()) || !v.allFinite()) {
        Malformed(obj_path, line_number, "bad vertex");
      }
      mesh.vertices.push_back(v);
    } else if (keyword == "vt") {
      Eigen::Vector2f uv;
      if (!(words >> uv.x() >> uv.y()) || !uv.allFinite()) {
        Malformed(obj_path, line_number, "bad texture coordinate");
      }
      uvs.push_back(uv);
    } else if (keyword == "f") {
      std::vector<std::string> corners;
      for (std::string word; words >> word;) corners.push_back(word);
      if (corners.size() != 3) Malformed(obj_path, line_number, "only triangles are supported");
      Eigen::Vector3i triangle, uv_triangle;
      for (int c = 0; c < 3; ++c) {
        std::tie(triangle[c], uv_triangle[c]) =
            ParseCorner(corners[static_cast<size_t>(c)], mesh, uvs.size(), obj_path, line_number);
      }
      mesh.triangles.push_back(triangle);
      uv_triangles.push_back(uv_triangle);
    } else if (keyword == "mtllib") {
      words >> mtllib;
    }
  }
  if (mtllib.empty()) throw BadInputError(obj_path.string() + ": no mtllib");
  mesh.corner_uvs.reserve(3 * uv_triangles.size());
  for (const Eigen::Vector3i& t : uv_triangles) {
    for (int c = 0; c < 3; ++c) mesh.corner_uvs.push_back(uvs[static_cast<size_t>(t[c])]);
  }
  mesh.atlas = ReadImage(AtlasPath(obj_path, mtllib));
  if (mesh.atlas.Channels() < 3) {
    throw BadInputError(obj_path.string() + ": the atlas must be an RGB image");
  }
  return mesh;
}

Eigen::Vector3f SampleBilinear(const Image& image, const Eigen::Vector2f& pixel) {
  const float x = std::clamp(pixel.x() - 0.5f, 0.0f, static_cast<float>(image.Width() - 1));
  const float y = std::clamp(pixel.y() - 0.5f, 0.0f, static_cast<float>(image.Height() - 1));
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.Width() - 1), y1 = std::min(y0 + 1, image.Height() - 1);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  Eigen::Vector3f colour;
  for (int c = 0; c < 3; ++c) {
    colour[c] = (1 - fy) * ((1 - fx) * image.At(x0, y0, c) + fx * image.At(x1, y0, c)) +
                fy * ((1 - fx) * image.At(x0, y1, c) + fx * image.At(x1, y1, c));
  }
  return colour;
}

Eigen::Vector3f SampleAtlas(const Image& atlas, const Eigen::Vector2f& uv) {
  // v runs up, rows run down.
  return SampleBilinear(atlas, Eigen::Vector2f(uv.x() * static_cast<float>(atlas.Width()),
                                               (1.0f - uv.y()) * static_cast<float>(atlas.Height())));
}

}  // namespace parallax

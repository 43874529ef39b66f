#include "geometry/ply.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// PLY's two spellings of each type (OpenMVS writes float32, uint8, ...), as the first one; an
// unknown type stays as it is.
std::string CanonicalType(const std::string& type) {
  static const std::map<std::string, std::string> names = {
      {"int8", "char"}, {"uint8", "uchar"}, {"int16", "short"}, {"uint16", "ushort"}, {"int32", "int"},
      {"uint32", "uint"}, {"float32", "float"}, {"float64", "double"}};
  const auto found = names.find(type);
  return found == names.end() ? type : found->second;
}

// Bytes of a canonical type; 0 for an unknown one.
size_t TypeSize(const std::string& type) {
  static const std::map<std::string, size_t> sizes = {{"char", 1}, {"uchar", 1}, {"short", 2}, {"ushort", 2},
                                                      {"int", 4},  {"uint", 4},  {"float", 4}, {"double", 8}};
  const auto found = sizes.find(type);
  return found == sizes.end() ? 0 : found->second;
}

struct Element {
  std::string name;
  size_t count = 0;
  size_t stride = 0;  // Bytes per record for fixed-size elements.
  std::vector<std::string> properties;  // "type name", or "list count_type index_type name".
};

struct Header {
  std::vector<Element> elements;
  std::vector<std::string> texture_files;  // "comment TextureFile NAME" lines (OpenMVS).
  size_t body = 0;  // Offset of the first data byte.
};

Header ParseHeader(const std::string& bytes, const fs::path& path) {
  const std::string kEnd = "end_header\n";
  const size_t end = bytes.find(kEnd);
  if (!bytes.starts_with("ply\n") || end == std::string::npos) {
    throw BadInputError(path.string() + ": not a PLY file");
  }
  Header header;
  header.body = end + kEnd.size();
  std::istringstream lines(bytes.substr(0, end));
  bool little_endian = false;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "comment") {
      std::string tag, name;
      words >> tag >> name;
      if (tag == "TextureFile" && !name.empty()) header.texture_files.push_back(name);
    } else if (keyword == "format") {
      std::string format;
      words >> format;
      little_endian = format == "binary_little_endian";
    } else if (keyword == "element") {
      Element element;
      words >> element.name >> element.count;
      if (!words) throw BadInputError(path.string() + ": malformed line '" + line + "'");
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) throw BadInputError(path.string() + ": property before element");
      Element& element = header.elements.back();
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, index_type, name;
        words >> count_type >> index_type >> name;
        count_type = CanonicalType(count_type);
        index_type = CanonicalType(index_type);
        if (TypeSize(count_type) == 0 || TypeSize(index_type) == 0) {
          throw BadInputError(path.string() + ": unsupported list property '" + line + "'");
        }
        element.properties.push_back("list " + count_type + " " + index_type + " " + name);
      } else {
        std::string name;
        words >> name;
        type = CanonicalType(type);
        if (TypeSize(type) == 0) {
          throw BadInputError(path.string() + ": unsupported property type '" + type + "'");
        }
        element.stride += TypeSize(type);
        element.properties.push_back(type + " " + name);
      }
    }
  }
  if (!little_endian) {
    throw BadInputError(path.string() + ": only binary_little_endian PLY files are supported");
  }
  return header;
}

template <typename T>
int64_t Load(const char* data) {
  T value;
  std::memcpy(&value, data, sizeof(T));
  return static_cast<int64_t>(value);
}

// Integer value of a list count or index stored as `type`.
int64_t LoadInteger(const std::string& type, const char* data) {
  if (type == "uchar") return Load<uint8_t>(data);
  if (type == "char") return Load<int8_t>(data);
  if (type == "ushort") return Load<uint16_t>(data);
  if (type == "short") return Load<int16_t>(data);
  if (type == "uint") return Load<uint32_t>(data);
  if (type == "int") return Load<int32_t>(data);
  return -1;  // Floating-point list types are not indices.
}

// The byte offset in a record of the three consecutive properties `type` a, b, c; nullopt
// when the element does not have them so.
std::optional<size_t> TripleOffset(const Element& element, const std::string& type,
                                   const std::array<std::string, 3>& names) {
  size_t offset = 0;
  for (size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i] == type + " " + names[0] && i + 2 < element.properties.size() &&
        element.properties[i + 1] == type + " " + names[1] &&
        element.properties[i + 2] == type + " " + names[2]) {
      return offset;
    }
    std::istringstream words(element.properties[i]);
    std::string property_type;
    words >> property_type;
    offset += TypeSize(property_type);
  }
  return std::nullopt;
}

void ReadVertices(const std::string& bytes, const Element& element, size_t& offset, NonFiniteVertices non_finite,
                  const fs::path& path, TriangleMesh& mesh) {
  if (element.properties.size() < 3 || element.properties[0] != "float x" ||
      element.properties[1] != "float y" || element.properties[2] != "float z") {
    throw BadInputError(path.string() + ": vertices must start with float x, y, z");
  }
  if (element.stride == 0 || (bytes.size() - offset) / element.stride < element.count) {
    throw BadInputError(path.string() + ": " + std::to_string(element.count) +
                        " vertices announced, the file is shorter");
  }
  const std::optional<size_t> normal = TripleOffset(element, "float", {"nx", "ny", "nz"});
  const std::optional<size_t> color = TripleOffset(element, "uchar", {"red", "green", "blue"});
  mesh.vertices.resize(element.count);
  if (normal) mesh.normals.resize(element.count);
  if (color) mesh.colors.resize(element.count);
  for (size_t i = 0; i < element.count; ++i) {
    const char* record = bytes.data() + offset + i * element.stride;
    std::memcpy(mesh.vertices[i].data(), record, 12);
    if (normal) std::memcpy(mesh.normals[i].data(), record + *normal, 12);
    if (color) std::memcpy(mesh.colors[i].data(), record + *color, 3);
    if (!mesh.vertices[i].allFinite() && non_finite == NonFiniteVertices::kRefuse) {
      throw BadInputError(path.string() + ": vertex " + std::to_string(i) + " is NaN or Inf");
    }
  }
  offset += element.count * element.stride;
}

// One face property: a list (count, then values) or a scalar.
struct FaceProperty {
  bool list = false;
  std::string count_type, value_type, name;
};

std::vector<FaceProperty> FaceProperties(const Element& element) {
  std::vector<FaceProperty> properties;
  for (const std::string& spec : element.properties) {
    std::istringstream words(spec);
    FaceProperty property;
    std::string first;
    words >> first;
    property.list = first == "list";
    if (property.list) {
      words >> property.count_type >> property.value_type >> property.name;
    } else {
      property.value_type = first;
      words >> property.name;
    }
    properties.push_back(property);
  }
  return properties;
}

// Faces: a vertex_indices list of 3, optionally a texcoord list of 6 floats (u, v per corner, as
// OpenMVS's TextureMesh writes them) and a texnumber (which atlas; only 0 is supported); other
// properties are skipped.
void ReadFaces(const std::string& bytes, const Element& element, size_t& offset,
               const fs::path& path, TriangleMesh& mesh) {
  const std::vector<FaceProperty> properties = FaceProperties(element);
  const auto has = [&](const std::string& name) {
    return std::any_of(properties.begin(), properties.end(),
                       [&](const FaceProperty& property) { return property.list && property.name == name; });
  };
  if (!has("vertex_indices") && !has("vertex_index")) {
    throw BadInputError(path.string() + ": faces must hold a vertex_indices list");
  }
  const std::string truncated = path.string() + ": face data is truncated";
  const auto take = [&](size_t size) {
    if (bytes.size() - offset < size) throw BadInputError(truncated);
    const char* data = bytes.data() + offset;
    offset += size;
    return data;
  };
  mesh.triangles.reserve(element.count);
  if (has("texcoord")) mesh.corner_uvs.reserve(3 * element.count);
  for (size_t f = 0; f < element.count; ++f) {
    const std::string face = path.string() + ": face " + std::to_string(f);
    for (const FaceProperty& property : properties) {
      const size_t value_size = TypeSize(property.value_type);
      if (!property.list) {
        const char* data = take(value_size);
        if (property.name == "texnumber" && LoadInteger(property.value_type, data) != 0) {
          throw BadInputError(face + " uses texture " + std::to_string(LoadInteger(property.value_type, data)) +
                              "; only meshes with one texture are supported");
        }
        continue;
      }
      const int64_t count = LoadInteger(property.count_type, take(TypeSize(property.count_type)));
      if (count < 0) throw BadInputError(face + ": negative list length");
      if ((bytes.size() - offset) / value_size < static_cast<size_t>(count)) throw BadInputError(truncated);
      if (property.name == "vertex_indices" || property.name == "vertex_index") {
        if (count != 3) {
          throw BadInputError(face + " has " + std::to_string(count) + " corners; only triangles are supported");
        }
        Eigen::Vector3i triangle;
        for (int c = 0; c < 3; ++c) {
          const int64_t index = LoadInteger(property.value_type, take(value_size));
          if (index < 0 || index >= static_cast<int64_t>(mesh.vertices.size())) {
            throw BadInputError(face + " refers to vertex " + std::to_string(index) + " of " +
                                std::to_string(mesh.vertices.size()));
          }
          triangle[c] = static_cast<int>(index);
        }
        mesh.triangles.push_back(triangle);
      } else if (property.name == "texcoord") {
        if (count != 6 || property.value_type != "float") {
          throw BadInputError(face + ": texcoord must be 6 floats, one u, v per corner");
        }
        for (int c = 0; c < 3; ++c) {
          Eigen::Vector2f uv;
          std::memcpy(uv.data(), take(8), 8);
          if (!uv.allFinite()) throw BadInputError(face + ": texcoord is NaN or Inf");
          mesh.corner_uvs.push_back(uv);
        }
      } else {
        take(value_size * static_cast<size_t>(count));
      }
    }
  }
}

// The one texture a textured PLY names, beside the file.
Image ReadAtlas(const fs::path& path, const std::vector<std::string>& texture_files) {
  if (texture_files.size() != 1) {
    throw BadInputError(path.string() + ": faces have texcoord, but the file names " +
                        std::to_string(texture_files.size()) +
                        " textures (comment TextureFile); only one is supported");
  }
  Image atlas = ReadImage(path.parent_path() / texture_files.front());
  if (atlas.Channels() < 3) throw BadInputError(path.string() + ": its texture must be an RGB image");
  return atlas;
}

// Leaves out the triangles with a NaN or Inf corner (and their texture coordinates).
void DropNonFiniteTriangles(TriangleMesh& mesh) {
  const bool uvs = mesh.corner_uvs.size() == 3 * mesh.triangles.size();
  size_t kept = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    bool finite = true;
    for (int c = 0; c < 3; ++c) finite = finite && mesh.vertices[static_cast<size_t>(triangle[c])].allFinite();
    if (!finite) continue;
    mesh.triangles[kept] = triangle;
    if (uvs) {
      for (size_t c = 0; c < 3; ++c) mesh.corner_uvs[3 * kept + c] = mesh.corner_uvs[3 * t + c];
    }
    ++kept;
  }
  mesh.triangles.resize(kept);
  if (uvs) mesh.corner_uvs.resize(3 * kept);
}

}  // namespace

TriangleMesh ReadPly(const fs::path& path, NonFiniteVertices non_finite) {
  const std::string bytes = ReadFileBytes(path);
  const Header header = ParseHeader(bytes, path);
  TriangleMesh mesh;
  size_t offset = header.body;
  bool has_vertices = false;
  for (const Element& element : header.elements) {
    if (element.name == "vertex") {
      ReadVertices(bytes, element, offset, non_finite, path, mesh);
      has_vertices = true;
    } else if (element.name == "face") {
      if (!has_vertices) throw BadInputError(path.string() + ": faces before vertices");
      ReadFaces(bytes, element, offset, path, mesh);
    } else {
      // Other elements come after the ones we read in every file we know; stop there.
      break;
    }
  }
  if (!has_vertices) throw BadInputError(path.string() + ": no vertex element");
  if (!mesh.corner_uvs.empty()) mesh.atlas = ReadAtlas(path, header.texture_files);
  if (non_finite == NonFiniteVertices::kDropTheirTriangles) DropNonFiniteTriangles(mesh);
  return mesh;
}

}  // namespace parallax

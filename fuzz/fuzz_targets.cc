#include "fuzz/fuzz_targets.h"

#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/error.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "geometry/ply.h"
#include "geometry/obj.h"
#include "reproject/novel_views.h"
#include "sfm/photo_conversion.h"
#include "sfm/photo_set.h"
#include "synth/scene.h"

namespace parallax::fuzz {
namespace fs = std::filesystem;
namespace {

// A two-image model with three points: the valid companions of a fuzzed model file.
SparseModel TinyModel() {
  SparseModel model;
  model.AddCamera(MakePinholeCamera(1, 64, 48, 50, 50, 32, 24));
  for (uint32_t id = 1; id <= 2; ++id) {
    SparseImage image;
    image.id = id;
    image.camera_id = 1;
    image.name = "000" + std::to_string(id) + ".png";
    image.cam_from_world.translation = Eigen::Vector3d(0.1 * id, 0, 0);
    for (uint64_t p = 1; p <= 3; ++p) {
      image.points2d.push_back({Eigen::Vector2d(10.0 * static_cast<double>(p), 20), p});
    }
    model.AddImage(image);
  }
  for (uint64_t p = 1; p <= 3; ++p) {
    Point3D point;
    point.id = p;
    point.xyz = Eigen::Vector3d(static_cast<double>(p), 0, 5);
    point.track = {{1, static_cast<uint32_t>(p - 1)}, {2, static_cast<uint32_t>(p - 1)}};
    model.AddPoint3D(point);
  }
  return model;
}

// A scratch folder per process, holding a valid model in both formats, into which each input
// is written under the name its reader expects.
const fs::path& Scratch() {
  static const fs::path dir = [] {
    const fs::path path = fs::temp_directory_path() / ("parallax_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(path);
    WriteSparseModel(TinyModel(), path / "binary", SparseFormat::kBinary);
    WriteSparseModel(TinyModel(), path / "text", SparseFormat::kText);
    WriteSparseModel(TinyModel(), path / "render", SparseFormat::kText);
    WriteImage(path / "photos" / "a.png", Image(16, 16, 3), PixelFormat::kUint8);
    WriteFileAtomically(Workspace(path).MeshDir() / "mesh.mtl", "newmtl atlas\nmap_Kd mesh.png\n");
    WriteImage(Workspace(path).MeshDir() / "mesh.png", Image(2, 2, 3), PixelFormat::kUint8);
    return path;
  }();
  return dir;
}

// Replaces `file` with the input bytes; returns its path.
fs::path Put(const fs::path& file, const uint8_t* data, size_t size) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

// Runs `read`, letting only BadInputError through (the readers' one way to refuse input).
template <typename Read>
void Expect(Read read) {
  try {
    read();
  } catch (const BadInputError&) {
  }
}

// The fuzzed file replaces one file of a valid model; the model is restored afterwards.
void SparseFile(const std::string& format, const std::string& file, const uint8_t* data,
                size_t size) {
  const fs::path dir = Scratch() / format;
  const std::string original = ReadFileBytes(dir / file);
  Put(dir / file, data, size);
  Expect([&] { ReadSparseModel(dir, format == "binary" ? SparseFormat::kBinary : SparseFormat::kText); });
  WriteFileAtomically(dir / file, original);
}

void BinaryCameras(const uint8_t* d, size_t n) { SparseFile("binary", "cameras.bin", d, n); }
void BinaryImages(const uint8_t* d, size_t n) { SparseFile("binary", "images.bin", d, n); }
void BinaryPoints(const uint8_t* d, size_t n) { SparseFile("binary", "points3D.bin", d, n); }
void TextCameras(const uint8_t* d, size_t n) { SparseFile("text", "cameras.txt", d, n); }
void TextImages(const uint8_t* d, size_t n) { SparseFile("text", "images.txt", d, n); }
void TextPoints(const uint8_t* d, size_t n) { SparseFile("text", "points3D.txt", d, n); }

void DenseArray(const uint8_t* data, size_t size) {
  const fs::path file = Put(Scratch() / "array.bin", data, size);
  Expect([&] { ReadColmapArray(file); });
}

void SceneJson(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Expect([&] { ParseSceneJson(text, "fuzz.json"); });
}

void Ply(const uint8_t* data, size_t size) {
  const fs::path file = Put(Scratch() / "input.ply", data, size);
  Expect([&] { ReadPly(file); });
}

void Obj(const uint8_t* data, size_t size) {
  const fs::path file = Put(Workspace(Scratch()).Mesh(), data, size);
  Expect([&] { ReadTexturedMesh(file); });
}

// The names a fuzzed image is given (OpenImageIO picks its reader by the name first); the
// input's first byte chooses one.
const std::vector<std::string>& ImageExtensions() {
  static const std::vector<std::string> extensions = {".png", ".jpg", ".tif", ".exr", ".bmp"};
  return extensions;
}

// An image as parallax reads it: with ReadImage, and as a photo beside a valid one (scanned
// from its header, decoded, and converted when COLMAP could not read it as it is).
void ImageFile(const uint8_t* data, size_t size) {
  if (size == 0) return;
  const fs::path folder = Scratch() / "photos";
  const std::string& extension = ImageExtensions()[data[0] % ImageExtensions().size()];
  const fs::path file = Put(folder / ("b" + extension), data + 1, size - 1);
  Expect([&] { ReadImage(file); });
  Expect([&] {
    for (const Photo& photo : ScanPhotos(folder).photos) {
      if (!photo.conversion.empty()) WriteReadablePhoto(folder / photo.name, Scratch() / "converted" / photo.name);
    }
  });
  fs::remove(file);
}

// The cameras file of a model given to `render --cameras`, turned into the cameras rendered
// (CamerasFromModel works out the camera each is rendered in, RenderedCamera).
void RenderCameras(const uint8_t* data, size_t size) {
  const fs::path folder = Scratch() / "render";
  Put(folder / "cameras.txt", data, size);
  Expect([&] { CamerasFromModel(folder); });
}

}  // namespace

const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {
      {"sparse_binary_cameras", BinaryCameras}, {"sparse_binary_images", BinaryImages},
      {"sparse_binary_points", BinaryPoints},   {"sparse_text_cameras", TextCameras},
      {"sparse_text_images", TextImages},       {"sparse_text_points", TextPoints},
      {"dense_array", DenseArray},              {"scene_json", SceneJson},
      {"ply", Ply},                             {"obj", Obj},
      {"image", ImageFile},                     {"render_cameras", RenderCameras}};
  return targets;
}

const Target& FindTarget(const std::string& name) {
  for (const Target& target : Targets()) {
    if (target.name == name) return target;
  }
  throw std::invalid_argument("no fuzz target named " + name);
}

void WriteSeeds(const fs::path& dir) {
  const fs::path& scratch = Scratch();
  const std::vector<std::pair<std::string, fs::path>> model_files = {
      {"sparse_binary_cameras", scratch / "binary" / "cameras.bin"},
      {"sparse_binary_images", scratch / "binary" / "images.bin"},
      {"sparse_binary_points", scratch / "binary" / "points3D.bin"},
      {"sparse_text_cameras", scratch / "text" / "cameras.txt"},
      {"sparse_text_images", scratch / "text" / "images.txt"},
      {"sparse_text_points", scratch / "text" / "points3D.txt"}};
  for (const auto& [target, file] : model_files) {
    WriteFileAtomically(dir / target / "seed_valid", ReadFileBytes(file));
  }
  DepthMap depth(4, 3);
  for (size_t i = 0; i < depth.Values().size(); ++i) depth.Values()[i] = 1.0f + static_cast<float>(i);
  WriteColmapDepth(dir / "dense_array" / "seed_depth", depth);
  // Three vertices (x y z float, red uchar) and one triangle.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  ply += std::string(3 * 13, '\0');
  ply += '\3';
  for (int32_t index : {0, 1, 2}) ply.append(reinterpret_cast<const char*>(&index), sizeof(index));
  WriteFileAtomically(dir / "ply" / "seed_mesh", ply);
  Image gradient(8, 6, 3);
  for (size_t i = 0; i < gradient.Pixels().size(); ++i) gradient.Pixels()[i] = static_cast<float>(i % 7) / 6.0f;
  for (size_t i = 0; i < ImageExtensions().size(); ++i) {
    const fs::path image = scratch / ("seed" + ImageExtensions()[i]);
    WriteImage(image, gradient, ImageExtensions()[i] == ".exr" ? PixelFormat::kHalf : PixelFormat::kUint8);
    std::string seed(1, static_cast<char>(i));  // The first byte picks the extension.
    seed += ReadFileBytes(image);
    WriteFileAtomically(dir / "image" / ("seed" + ImageExtensions()[i]), seed);
  }
  WriteFileAtomically(dir / "render_cameras" / "seed_pinhole", ReadFileBytes(scratch / "render" / "cameras.txt"));
  WriteFileAtomically(dir / "render_cameras" / "seed_opencv", "1 OPENCV 64 48 50 50 32 24 0.1 0.01 0.001 -0.002\n");
  WriteFileAtomically(dir / "obj" / "seed_triangle",
                      "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                      "usemtl atlas\nf 1/1 2/2 3/3\n");
}

}  // namespace parallax::fuzz

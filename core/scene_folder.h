#pragma once
// Paths of the scene-folder layout (docs/design.md): what `synth` writes and `evaluate` reads.
#include <filesystem>
#include <string>

namespace parallax {

// One set of views with ground truth: the training set at the scene root, or novel/.
struct ViewSetPaths {
  std::filesystem::path images;  // <name>.png
  std::filesystem::path sparse;  // COLMAP text model (points3D.txt empty)
  std::filesystem::path depth;   // <stem>.exr, float32 z-depth, 0 = background
  std::filesystem::path normal;  // <stem>.exr, optional, camera-frame unit normals
  // Optional per-photo color gains (core/color_gains.h) applied as the photos are read;
  // empty or missing: none.
  std::filesystem::path color_gains;

  std::filesystem::path DepthFor(const std::string& image_name) const;
  std::filesystem::path NormalFor(const std::string& image_name) const;
};

// The files a scene's geometry is read from (ReadSceneGeometry, geometry/scene_frame.h): a mesh
// (OBJ, with its material) and a cloud (PLY). A path that names no file stands for none.
struct SceneFiles {
  std::filesystem::path mesh;
  std::filesystem::path cloud;
};

struct SceneFolder {
  std::filesystem::path root;

  std::filesystem::path SceneJson() const { return root / "scene.json"; }
  // Present in a scene folder, absent from a workspace.
  std::filesystem::path GroundTruth() const { return root / "gt"; }
  ViewSetPaths Training() const;
  ViewSetPaths Novel() const;
};

}  // namespace parallax

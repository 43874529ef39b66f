#include "core/scene_folder.h"

namespace parallax {
namespace fs = std::filesystem;

fs::path ViewSetPaths::DepthFor(const std::string& image_name) const {
  return depth / (fs::path(image_name).stem().string() + ".exr");
}

fs::path ViewSetPaths::NormalFor(const std::string& image_name) const {
  return normal / (fs::path(image_name).stem().string() + ".exr");
}

// No color gains: a scene's photos are rendered under one exposure.
ViewSetPaths SceneFolder::Training() const {
  return {root / "images", root / "gt" / "sparse", root / "gt" / "depth", root / "gt" / "normal", {}};
}

ViewSetPaths SceneFolder::Novel() const {
  const fs::path novel = root / "novel";
  return {novel / "images", novel / "sparse", novel / "depth", novel / "normal", {}};
}

}  // namespace parallax

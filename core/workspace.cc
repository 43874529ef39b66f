#include "core/workspace.h"

#include "core/error.h"

namespace parallax {
namespace {

std::string PassSuffix(StereoPass pass) {
  return pass == StereoPass::kPhotometric ? ".photometric.bin" : ".geometric.bin";
}

std::string Stem(const std::string& photo) { return std::filesystem::path(photo).stem().string(); }

}  // namespace

std::filesystem::path Workspace::StereoDepthMap(const std::string& photo, StereoPass pass) const {
  return StereoDepthMaps() / (photo + PassSuffix(pass));
}

std::filesystem::path Workspace::StereoNormalMap(const std::string& photo, StereoPass pass) const {
  return StereoNormalMaps() / (photo + PassSuffix(pass));
}

std::filesystem::path Workspace::Depth(const std::string& photo) const {
  return DepthDir() / (Stem(photo) + ".exr");
}

std::filesystem::path Workspace::DepthConfidence(const std::string& photo) const {
  return DepthDir() / (Stem(photo) + ".confidence.exr");
}

ViewSetPaths Workspace::Sources() const {
  ViewSetPaths paths;
  paths.images = Images();
  paths.sparse = Sparse();
  paths.depth = DepthDir();
  paths.color_gains = ColorGainsFile();
  return paths;
}

ViewSetPaths SourcePathsFor(const std::filesystem::path& root) {
  namespace fs = std::filesystem;
  const Workspace workspace(root);
  if (fs::is_directory(workspace.Sparse()) && fs::is_directory(workspace.Images())) return workspace.Sources();
  const SceneFolder scene{root};
  if (fs::is_directory(scene.Training().sparse) && fs::is_directory(scene.Training().depth)) {
    return scene.Training();
  }
  throw BadInputError(root.string() + " is neither a workspace (sparse/, images/: run parallax "
                      "reconstruct) nor a scene folder (gt/sparse, gt/depth)");
}

}  // namespace parallax

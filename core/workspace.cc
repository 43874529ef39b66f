#include "core/workspace.h"

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

}  // namespace parallax

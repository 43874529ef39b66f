#pragma once
// What `evaluate` writes into a workspace (docs/design.md, "Workspace"): the workspace's own
// layout (core/workspace.h) knows nothing of evaluation.
#include <filesystem>
#include <utility>

namespace parallax {

class EvaluationLayout {
 public:
  explicit EvaluationLayout(std::filesystem::path workspace) : root_(std::move(workspace)) {}

  std::filesystem::path Json() const { return root_ / "evaluation.json"; }
  std::filesystem::path Dir() const { return root_ / "evaluation"; }
  std::filesystem::path DepthErrorImages() const { return Dir() / "depth_error"; }
  std::filesystem::path MeshRenders() const { return Dir() / "mesh_render"; }
  std::filesystem::path MeshHeldOutRenders() const { return Dir() / "mesh_held_out"; }
  std::filesystem::path NovelRegistration() const { return Dir() / "novel_registration"; }
  std::filesystem::path NovelComparisons(bool ground_truth_sources) const {
    return Dir() / (ground_truth_sources ? "novel_gt_sources" : "novel");
  }

 private:
  std::filesystem::path root_;
};

}  // namespace parallax

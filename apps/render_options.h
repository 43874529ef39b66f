#pragma once
// The novel-view knobs `render` and `evaluate` share: --sources, --warp, --fill.
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "reproject/novel_views.h"
#include "reproject/render.h"
#include "reproject/source_selection.h"

namespace parallax {

struct NovelViewSettings {
  SourceSelectionOptions selection;
  RenderOptions render;
  // --warp naive: the baseline to beat, a nearest-pixel point warp of each source without
  // footprints or background at infinity.
  std::string warp = "mesh";
  // --depth-holes: "mesh" fills the pixels a workspace's depth maps have no depth for from
  // its mesh (when reconstruct made one), "none" leaves them holes.
  std::string depth_holes = "mesh";
  // Applies `warp` to `render`; call before using the settings.
  void Resolve();
};

void AddRenderOptions(CLI::App& command, NovelViewSettings& settings);

// With depth_holes "mesh" and <workspace>/mesh/mesh.obj present, makes `library` fill each
// source's depth holes with the mesh's depth (Embree, one ray per pixel, when the view is
// loaded). Returns what it did or why not, for the log and render's report.json.
std::string UseMeshForDepthHoles(const std::filesystem::path& workspace,
                                 const NovelViewSettings& settings, SourceLibrary* library);

}  // namespace parallax

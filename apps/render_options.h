#pragma once
// The novel-view knobs `render` and `evaluate` share: --sources, --warp, --fill.
#include <CLI/CLI.hpp>

#include "reproject/render.h"
#include "reproject/source_selection.h"

namespace parallax {

struct NovelViewSettings {
  SourceSelectionOptions selection;
  RenderOptions render;
  // --warp naive: the baseline to beat, a nearest-pixel point warp of each source without
  // footprints or background at infinity.
  std::string warp = "mesh";
  // Applies `warp` to `render`; call before using the settings.
  void Resolve();
};

void AddRenderOptions(CLI::App& command, NovelViewSettings& settings);

}  // namespace parallax

#pragma once
// The novel-view options `render` and `evaluate` share: --sources, --hole-sources, --warp,
// --texture-filter, --fill, --depth-holes, --edge-erosion.
#include <CLI/CLI.hpp>

#include "reproject/workspace_depth.h"

namespace parallax {

void AddNovelViewOptions(CLI::App& command, NovelViewSettings& settings);

}  // namespace parallax

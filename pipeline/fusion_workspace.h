#pragma once
// Fusion over a workspace (mvs/fusion.h): the views of <ws>/sparse with a depth map under
// <ws>/depth and a geometric normal map under <ws>/stereo/normal_maps, their photos from
// <ws>/images, colors corrected by <ws>/color_gains.json when present.
#include "core/progress.h"
#include "core/workspace.h"
#include "mvs/fusion.h"

namespace parallax {

// Each view's maps and photo are read when fusion needs them (at most max_neighbours + 1
// views in memory). Views without a depth map are left out. Deterministic.
FusedPoints FuseWorkspace(const Workspace& workspace, const FusionOptions& options, Progress& progress);

}  // namespace parallax

#pragma once
// The image pyramid of PatchMatch's coarse-to-fine levels (internal to mvs/: used by
// patch_match.cc): a view at half resolution, and a coarse level's planes carried to the finer
// level.
#include "core/camera.h"
#include "mvs/patch_match.h"

namespace parallax {

// The view at half its size (2x2 box filter), its camera scaled so that pixel centres map
// exactly.
StereoView HalfResolution(const StereoView& view);

// Each fine pixel takes the plane of the coarse pixel it lies in, intersected with its own ray
// (planes are 3D: the same in every level's camera); its cost is `invalid_cost`, to be scored.
DepthNormalMap UpsamplePlanes(const DepthNormalMap& coarse, const Camera& coarse_camera,
                              const Camera& fine_camera, float invalid_cost);

}  // namespace parallax

#pragma once
// Photo color for filled holes: where a source saw the surface a hole's fill continues but
// had no depth there (a white wall, smooth ground), the hole takes that source's color.
#include <span>
#include <vector>

#include "core/depth_map.h"
#include "core/image.h"
#include "reproject/blend.h"
#include "reproject/holes.h"
#include "reproject/view.h"

namespace parallax {

// A source as the fill looks it up.
struct FillSource {
  PosedCamera camera;
  const Image* color = nullptr;    // Linear RGB, camera size, as the warp blends it.
  const DepthMap* depth = nullptr;  // Camera size.
  // MarkBackground of depth and color (sky); null or empty: no depth-0 pixel is sky.
  const std::vector<uint8_t>* background = nullptr;
};

struct FillFromSourcesSummary {
  int colored_px = 0;  // Hole pixels that took the sources' color.
};

// For every hole pixel (crack or disocclusion) that the fill gave a surface depth, the point at
// that depth on its ray is looked up in every source that contains it: a source whose depth
// there is unknown (and not sky), or agrees with the point within 5%, saw that surface, and
// its color there, bilinear, joins a blend weighted by the angle between its ray and the
// target's (Unstructured-Lumigraph style); a source that sees something in front of the point,
// or past it, does not. Where at least one source saw it, the pixel's color is that blend
// instead of the fill's; its depth and sample kind stay. Parallel over rows.
// Throws InternalError for a source without color or depth, or of another size than
// its camera, or a class map of another size than the blend.
FillFromSourcesSummary FillFromSources(const ClassMap& classes, const PosedCamera& target,
                                       std::span<const FillSource> sources, BlendResult* blend);

}  // namespace parallax

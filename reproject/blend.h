#pragma once
// Blending of several sources' warped samples into one target image.
#include <cstdint>
#include <span>
#include <vector>

#include "core/depth_map.h"
#include "core/image.h"
#include "reproject/forward_warp.h"

namespace parallax {

struct BlendOptions {
  // Samples within this relative depth of the front-most one at a pixel are one surface and
  // are blended; farther ones are occluded. In (0, 1). 5%, as ErodeDepthEdges separates
  // occluders from their background: 1% split one surface into front and behind wherever the
  // sources' depths disagree by a little (estimated depth, sampling), and one source's sample
  // stood alone.
  double depth_tolerance = 0.05;
  // The surface blended at a pixel is the front-most one that this many sources' samples
  // agree on (within depth_tolerance; fewer where fewer sources landed there; the front-most
  // sample when no two agree). A sample in front of what the others agree on is more often a
  // depth error of its source than an occluder only it sees. 1: always the front-most; in
  // [1, 16].
  int min_support = 2;

  void Check() const;  // Throws UsageError naming the field and value.
};

// What landed on a target pixel.
enum class SampleKind : uint8_t { kNone, kSurface, kBackground };

struct BlendResult {
  Image color;                   // Linear RGB, target size; 0 where nothing landed.
  DepthMap depth;                // Surface z-depth; 0 for background and where nothing landed.
  std::vector<SampleKind> kind;  // Row-major, one per pixel.

  SampleKind Kind(int x, int y) const {
    return kind[static_cast<size_t>(y) * static_cast<size_t>(color.Width()) +
                static_cast<size_t>(x)];
  }
};

// Per pixel: the front-most surface depth over all buffers (with min_support); the surface
// samples within depth_tolerance of it are averaged in linear light with their weights
// (WarpBuffer::Weight: smaller angle between source and target rays, less stretch -> larger).
// Background samples are blended only where no surface sample landed. Parallel over rows.
// Overwrites *out, keeping its memory when large enough (a frame loop reuses one).
// Throws InternalError for no buffers or buffers of different sizes.
void Blend(std::span<const WarpBuffer> buffers, const BlendOptions& options, BlendResult* out);

}  // namespace parallax

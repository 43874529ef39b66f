#pragma once
// Which "no value" pixels of a depth map are background at infinity, and which values are
// noise.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/depth_map.h"
#include "core/image.h"

namespace parallax {

// Marks the depth-0 pixels that are 4-connected to the image's top row or the upper half of
// its sides through depth-0 pixels smooth in color: in our outdoor scenes that is the sky and
// the far background (photos are upright), which a
// renderer warps as directions (rotation only). A pixel is smooth when every channel of
// `color` (linear RGB, the depth's size) is within max_step x the larger value (+ 0.002, for
// dark noise) of each 4-neighbour's: a sky gradient is, the ground is not (pixels next to
// one with depth pass: silhouettes mix colors). Depth-0 pixels
// enclosed by valid depth, on textured ground the depth estimate missed, or on smooth ground
// reaching the border only below the scene, are unknown, not background: they stay holes
// rather than land at infinity. max_step >= 1 turns the color test off. Returns one byte per pixel, row-major,
// 1 = background. Throws InternalError when the sizes differ.
std::vector<uint8_t> MarkBackground(const DepthMap& depth, const Image& color, float max_step);
// The same into *background, reusing its memory and that of *stack (scratch for the fill).
void MarkBackground(const DepthMap& depth, const Image& color, float max_step,
                    std::vector<uint8_t>* background, std::vector<size_t>* stack);

// Sets to 0 (no value) every speckle: a 4-connected patch of depth values, neighbours within
// max_step relative depth of each other, of at most max_pixels pixels. Estimated depth maps
// carry such specks in the sky and along occluding edges; warped, they float in front of the
// sky and the fill smears them into streaks. Returns how many values were cleared. Throws
// InternalError for max_step <= 0.
int RemoveDepthSpeckles(DepthMap* depth, int max_pixels, float max_step);

// Sets to 0 the pixels of `depth` on the near side of a depth edge: within `pixels` (4-steps)
// of a 4-neighbour more than max_step relative depth farther away, along the near surface.
// A photo mixes the two surfaces' colors in its edge pixels, and estimated depth puts them on
// the near surface (foreground fattening): warped, they draw a halo of the background color
// around every occluder. Without them the near surface stops a pixel short and the other
// sources (or the fill) give the background there. Returns how many values were cleared.
// Throws InternalError for max_step <= 0 or pixels < 0.
int ErodeDepthEdges(DepthMap* depth, float max_step, int pixels);

}  // namespace parallax

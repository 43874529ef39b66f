#pragma once
// Which "no value" pixels of a depth map are background at infinity.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/depth_map.h"

namespace parallax {

// Marks the depth-0 pixels that are 4-connected to the image border through depth-0 pixels:
// in our outdoor scenes that is the sky and the far background, which a renderer warps as
// directions (rotation only). Depth-0 pixels enclosed by valid depth are unknown, not
// background: the depth estimate failed there, and they stay holes. Returns one byte per
// pixel, row-major, 1 = background.
std::vector<uint8_t> MarkBackground(const DepthMap& depth);
// The same into *background, reusing its memory and that of *stack (scratch for the fill).
void MarkBackground(const DepthMap& depth, std::vector<uint8_t>* background,
                    std::vector<size_t>* stack);

}  // namespace parallax

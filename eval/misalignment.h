#pragma once
// Misalignment of a render with the photo it should match (docs/design.md evaluate JSON,
// `misalignment_px`): dense optical flow from the render to the photo, needing no ground truth.
// Where the cameras are right the flow is a fraction of a pixel; a pose or intrinsics error
// shows as flow that follows the whole frame, which no photometric figure separates from blur.
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace parallax {

// At each pixel of `render`, how far (px) the photo shows the same content: the length of the
// dense optical flow from `render` to `photo` (both sRGB, same size, 3 or 4 channels; OpenCV's
// DIS flow on their luma, patch means normalised). One channel. Throws InternalError for
// images of different sizes.
Image FlowLength(const Image& render, const Image& photo);

// The pixels of `photo` (sRGB, 3 or 4 channels) whose neighbourhood has texture in two
// directions, where a flow is determined: the smaller eigenvalue of the luma's structure tensor
// (OpenCV's cornerMinEigenVal, 5 px window, 3 px Sobel) at least 1e-4. Flat sky or plaster leaves
// the flow free (on a rendered courtyard photo shifted by 1.35 px, the flow's 90th percentile is
// 3.0 px off over all pixels, 0.12 px over these 65%).
std::vector<uint8_t> TexturedPixels(const Image& photo);

// The flow's median and 90th percentile (px) over the pixels where `mask` is set (0 for none).
// Throws InternalError for a mask of another size.
struct Misalignment {
  double median_px = 0;
  double p90_px = 0;
};
Misalignment MisalignmentOf(const Image& flow_length, const std::vector<uint8_t>& mask);

}  // namespace parallax

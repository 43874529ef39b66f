#pragma once
// Image quality against a reference, as docs/design.md's evaluate JSON defines it: on sRGB values
// in [0, 1], color channels only (alpha ignored).
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace parallax {

// Peak signal-to-noise ratio in dB over the pixels where `mask` is non-zero (all pixels for an
// empty mask). Identical images give 100 dB (the MSE is floored at 1e-10), no pixel gives 0.
// Throws InternalError for images of different sizes or with fewer than 3 channels.
double Psnr(const Image& image, const Image& reference, const std::vector<uint8_t>& mask = {});

// Mean structural similarity (Wang et al. 2004: Gaussian window, sigma 1.5, radius 5,
// K1 = 0.01, K2 = 0.03) of the luma (Rec. 709 weights), over every pixel. Same checks as Psnr.
double Ssim(const Image& image, const Image& reference);

}  // namespace parallax

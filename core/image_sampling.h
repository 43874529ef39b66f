#pragma once
// Colors of an image between its pixel centres.
#include <Eigen/Core>

#include "core/image.h"

namespace parallax {

// Color (first 3 channels) at a continuous pixel position (pixel centres at integer + 0.5),
// bilinear between pixel centres, clamped at the border.
Eigen::Vector3f SampleBilinear(const Image& image, const Eigen::Vector2f& pixel);

}  // namespace parallax

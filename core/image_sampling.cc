#include "core/image_sampling.h"

#include <algorithm>

namespace parallax {

Eigen::Vector3f SampleBilinear(const Image& image, const Eigen::Vector2f& pixel) {
  const float x = std::clamp(pixel.x() - 0.5f, 0.0f, static_cast<float>(image.Width() - 1));
  const float y = std::clamp(pixel.y() - 0.5f, 0.0f, static_cast<float>(image.Height() - 1));
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.Width() - 1), y1 = std::min(y0 + 1, image.Height() - 1);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  Eigen::Vector3f color;
  for (int c = 0; c < 3; ++c) {
    color[c] = (1 - fy) * ((1 - fx) * image.At(x0, y0, c) + fx * image.At(x1, y0, c)) +
                fy * ((1 - fx) * image.At(x0, y1, c) + fx * image.At(x1, y1, c));
  }
  return color;
}

}  // namespace parallax

#include "mvs/working_resolution.h"

#include <algorithm>
#include <cmath>

namespace parallax {

double WorkingScale(int width, int height, double image_scale, int max_image_size) {
  const int long_side = std::max(width, height);
  if (max_image_size == 0 || long_side <= 0) return image_scale;
  return std::min(image_scale, static_cast<double>(max_image_size) / static_cast<double>(long_side));
}

Camera WorkingCamera(const Camera& camera, double scale) {
  if (scale == 1) return camera;
  const auto width = static_cast<uint64_t>(std::max(1L, std::lround(static_cast<double>(camera.width) * scale)));
  const auto height = static_cast<uint64_t>(std::max(1L, std::lround(static_cast<double>(camera.height) * scale)));
  const double sx = static_cast<double>(width) / static_cast<double>(camera.width);
  const double sy = static_cast<double>(height) / static_cast<double>(camera.height);
  return MakePinholeCamera(camera.id, width, height, camera.FocalX() * sx, camera.FocalY() * sy,
                           camera.PrincipalX() * sx, camera.PrincipalY() * sy);
}

}  // namespace parallax

#include "viewer/matcap.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace parallax {

std::vector<float> BlinnPhongMatcap(int size, const Eigen::Vector3d& towards_light_in_camera, double specular,
                                    double shininess) {
  const Eigen::Vector3d light = towards_light_in_camera.normalized();
  const Eigen::Vector3d half = (light + Eigen::Vector3d(0, 0, -1)).normalized();
  std::vector<float> texels(static_cast<size_t>(size) * static_cast<size_t>(size));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      Eigen::Vector2d st(2 * (x + 0.5) / size - 1, 2 * (y + 0.5) / size - 1);
      if (st.squaredNorm() > 1) st.normalize();
      const Eigen::Vector3d normal(st.x(), st.y(), -std::sqrt(std::max(0.0, 1 - st.squaredNorm())));
      const double value = normal.dot(light) > 0 ? specular * std::pow(std::max(normal.dot(half), 0.0), shininess) : 0;
      texels[static_cast<size_t>(y) * static_cast<size_t>(size) + static_cast<size_t>(x)] = static_cast<float>(value);
    }
  }
  return texels;
}

}  // namespace parallax

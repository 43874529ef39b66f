#include "mvs/stereo_pyramid.h"

#include <algorithm>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace parallax {

StereoView HalfResolution(const StereoView& view) {
  StereoView half;
  half.cam_from_world = view.cam_from_world;
  half.camera = view.camera;
  half.image.width = view.image.width / 2;
  half.image.height = view.image.height / 2;
  half.camera.width = static_cast<uint64_t>(half.image.width);
  half.camera.height = static_cast<uint64_t>(half.image.height);
  // Pixel centres at +0.5 make the continuous coordinates scale exactly by one half.
  const double sx = static_cast<double>(half.image.width) / view.image.width;
  const double sy = static_cast<double>(half.image.height) / view.image.height;
  if (half.camera.model == CameraModel::kSimplePinhole) {
    half.camera.model = CameraModel::kPinhole;
    half.camera.params = {view.camera.params[0], view.camera.params[0], view.camera.params[1],
                          view.camera.params[2]};
  }
  half.camera.params[0] *= sx;
  half.camera.params[1] *= sy;
  half.camera.params[2] *= sx;
  half.camera.params[3] *= sy;
  half.image.values.resize(static_cast<size_t>(half.image.width) * half.image.height);
  for (int y = 0; y < half.image.height; ++y) {
    for (int x = 0; x < half.image.width; ++x) {
      half.image.values[static_cast<size_t>(y) * half.image.width + x] =
          0.25f * (view.image.At(2 * x, 2 * y) + view.image.At(2 * x + 1, 2 * y) +
                   view.image.At(2 * x, 2 * y + 1) + view.image.At(2 * x + 1, 2 * y + 1));
    }
  }
  return half;
}

DepthNormalMap UpsamplePlanes(const DepthNormalMap& coarse, const Camera& coarse_camera,
                              const Camera& fine_camera, float invalid_cost) {
  const int width = static_cast<int>(fine_camera.width), height = static_cast<int>(fine_camera.height);
  DepthNormalMap fine{DepthMap(width, height), std::vector<float>(static_cast<size_t>(width) * height * 3, 0.0f),
                      std::vector<float>(static_cast<size_t>(width) * height, invalid_cost)};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int cx = std::min(x / 2, coarse.depth.Width() - 1);
      const int cy = std::min(y / 2, coarse.depth.Height() - 1);
      const float depth = coarse.depth.At(cx, cy);
      if (!(depth > 0)) continue;
      const size_t ci = static_cast<size_t>(cy) * coarse.depth.Width() + cx;
      const Eigen::Vector3d normal(coarse.normal[3 * ci], coarse.normal[3 * ci + 1], coarse.normal[3 * ci + 2]);
      const double rho = static_cast<double>(depth) * normal.dot(*coarse_camera.Unproject({cx + 0.5, cy + 0.5}));
      const double n_dot_ray = normal.dot(*fine_camera.Unproject({x + 0.5, y + 0.5}));
      if (!(n_dot_ray < 0)) continue;
      const size_t i = static_cast<size_t>(y) * width + x;
      fine.depth.At(x, y) = static_cast<float>(rho / n_dot_ray);
      std::copy_n(&coarse.normal[3 * ci], 3, &fine.normal[3 * i]);
    }
  }
  return fine;
}

}  // namespace parallax

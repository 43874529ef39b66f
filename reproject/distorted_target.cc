#include "reproject/distorted_target.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "core/error.h"

namespace parallax {
namespace {

// The undistorted normalised coordinates of pixel position (u, v) of `camera`.
std::optional<Eigen::Vector2d> UndistortedAt(const Camera& camera, double u, double v) {
  const Eigen::Vector2d distorted((u - camera.PrincipalX()) / camera.FocalX(), (v - camera.PrincipalY()) / camera.FocalY());
  return camera.Undistort(distorted);
}

}  // namespace

Camera PinholeCovering(const Camera& camera) {
  const double width = static_cast<double>(camera.width), height = static_cast<double>(camera.height);
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  constexpr int kSteps = 64;  // Points along each side of the border.
  for (int i = 0; i <= kSteps; ++i) {
    const double s = static_cast<double>(i) / kSteps;
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(s * width, 0), Eigen::Vector2d(s * width, height),
                                         Eigen::Vector2d(0, s * height), Eigen::Vector2d(width, s * height)}) {
      if (const auto normalized = UndistortedAt(camera, pixel.x(), pixel.y())) {
        low = low.cwiseMin(*normalized);
        high = high.cwiseMax(*normalized);
      }
    }
  }
  if (!(low.x() < high.x() && low.y() < high.y())) {
    throw BadInputError("camera " + std::to_string(camera.id) + ": its distortion cannot be inverted anywhere "
                        "on its image border");
  }
  const double fx = camera.FocalX(), fy = camera.FocalY();
  // Clamped to twice the image on each side of the principal point's share of it.
  low.x() = std::max(low.x(), -2 * camera.PrincipalX() / fx);
  low.y() = std::max(low.y(), -2 * camera.PrincipalY() / fy);
  high.x() = std::min(high.x(), 2 * (width - camera.PrincipalX()) / fx);
  high.y() = std::min(high.y(), 2 * (height - camera.PrincipalY()) / fy);
  if (!(low.x() < high.x() && low.y() < high.y())) {  // A principal point far off the image.
    throw BadInputError("camera " + std::to_string(camera.id) + ": its principal point lies too far outside "
                        "its image to render it");
  }
  const double left = std::floor(low.x() * fx), top = std::floor(low.y() * fy);
  const auto pinhole_width = static_cast<uint64_t>(std::ceil(high.x() * fx) - left);
  const auto pinhole_height = static_cast<uint64_t>(std::ceil(high.y() * fy) - top);
  return MakePinholeCamera(camera.id, std::max<uint64_t>(1, pinhole_width), std::max<uint64_t>(1, pinhole_height), fx,
                           fy, -left, -top);
}

PosedCamera RenderedCamera(const PosedCamera& target) {
  if (!target.camera.HasDistortion()) return target;
  return {PinholeCovering(target.camera), target.cam_from_world};
}

void ResampleIntoDistorted(const Camera& camera, const Camera& pinhole, RenderResult* result) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  const int source_width = result->color.Width(), source_height = result->color.Height();
  RenderResult out;
  out.color.Reset(width, height, 3);
  out.depth.Reset(width, height);
  out.classes.width = width;
  out.classes.height = height;
  out.classes.classes.assign(static_cast<size_t>(width) * static_cast<size_t>(height), PixelClass::kOutOfView);
  const bool sky_known = !result->classes.open_to_sky.empty();
  if (sky_known) out.classes.open_to_sky.assign(out.classes.classes.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::optional<Eigen::Vector2d> normalized = UndistortedAt(camera, x + 0.5, y + 0.5);
      if (!normalized) continue;
      // Pixel position in the pinhole image, and its nearest pixel.
      const double u = normalized->x() * pinhole.FocalX() + pinhole.PrincipalX();
      const double v = normalized->y() * pinhole.FocalY() + pinhole.PrincipalY();
      if (!(u >= 0 && v >= 0 && u < source_width && v < source_height)) continue;
      const int nx = static_cast<int>(u), ny = static_cast<int>(v);
      const size_t to = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      out.classes.classes[to] = result->classes.At(nx, ny);
      if (sky_known) out.classes.open_to_sky[to] = result->classes.OpenToSky(nx, ny) ? 1 : 0;
      out.depth.At(x, y) = result->depth.At(nx, ny);
      // Bilinear between the four pixel centres around (u, v), clamped at the border.
      const double fx = u - 0.5, fy = v - 0.5;
      const int x0 = std::clamp(static_cast<int>(std::floor(fx)), 0, source_width - 1);
      const int y0 = std::clamp(static_cast<int>(std::floor(fy)), 0, source_height - 1);
      const int x1 = std::min(x0 + 1, source_width - 1), y1 = std::min(y0 + 1, source_height - 1);
      const float ax = static_cast<float>(std::clamp(fx - x0, 0.0, 1.0));
      const float ay = static_cast<float>(std::clamp(fy - y0, 0.0, 1.0));
      for (int c = 0; c < 3; ++c) {
        const float top = (1 - ax) * result->color.At(x0, y0, c) + ax * result->color.At(x1, y0, c);
        const float bottom = (1 - ax) * result->color.At(x0, y1, c) + ax * result->color.At(x1, y1, c);
        out.color.At(x, y, c) = (1 - ay) * top + ay * bottom;
      }
    }
  }
  out.metrics = ComputeHoleMetrics(out.classes);
  out.fill = result->fill;
  out.timings = result->timings;
  *result = std::move(out);
}

}  // namespace parallax

#include "reproject/view.h"

#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace parallax {

Pinhole Pinhole::From(const Camera& camera) {
  const std::string name = "camera " + std::to_string(camera.id);
  camera.Check();
  if (!IsProjectionSupported(camera.model) || camera.HasDistortion()) {
    throw InternalError(name + ": reproject needs an undistorted pinhole camera, got " +
                        std::string(CameraModelName(camera.model)) +
                        " with distortion");
  }
  constexpr uint64_t kMaxSide = static_cast<uint64_t>(std::numeric_limits<int>::max() / 4);
  if (camera.width > kMaxSide || camera.height > kMaxSide) {
    throw InternalError(name + ": size " + std::to_string(camera.width) + "x" +
                        std::to_string(camera.height) + " is too large");
  }
  Pinhole pinhole;
  pinhole.width = static_cast<int>(camera.width);
  pinhole.height = static_cast<int>(camera.height);
  pinhole.fx = camera.FocalX();
  pinhole.fy = camera.FocalY();
  pinhole.cx = camera.PrincipalX();
  pinhole.cy = camera.PrincipalY();
  if (!(pinhole.fx > 0) || !(pinhole.fy > 0)) {
    throw InternalError(name + ": focal length must be positive, got fx " +
                        std::to_string(pinhole.fx) + ", fy " +
                        std::to_string(pinhole.fy));
  }
  return pinhole;
}

void CheckSourceView(const SourceView& view) {
  const std::string name = "source view '" + view.name + "'";
  const Pinhole pinhole = Pinhole::From(view.camera);
  if (view.color.Channels() != 3) {
    throw InternalError(name + ": color must have 3 channels, got " +
                        std::to_string(view.color.Channels()));
  }
  const auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
  if (view.color.Width() != pinhole.width || view.color.Height() != pinhole.height ||
      view.depth.Width() != pinhole.width || view.depth.Height() != pinhole.height) {
    throw InternalError(name + ": camera " + size(pinhole.width, pinhole.height) +
                        ", color " + size(view.color.Width(), view.color.Height()) +
                        " and depth " + size(view.depth.Width(), view.depth.Height()) +
                        " must have the same size");
  }
}

}  // namespace parallax

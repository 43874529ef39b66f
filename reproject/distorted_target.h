#pragma once
// Targets with lens distortion (SIMPLE_RADIAL, RADIAL, OPENCV): rendered in a pinhole camera
// that sees everything they see, then resampled through the distortion into their pixels.
#include "core/camera.h"
#include "reproject/render.h"
#include "reproject/view.h"

namespace parallax {

// A distortion-free camera with `camera`'s focal lengths whose image holds the undistorted
// image of `camera`'s: the bounding box of its undistorted border (at most twice its size on
// a side, for distortions that fold the corners away). Throws BadInputError (only the camera's
// values can say) when no border pixel can be undistorted or the principal point lies too far
// outside the image; the caller that read the camera adds the file's name.
Camera PinholeCovering(const Camera& camera);

// The camera a target is rendered in: itself without distortion, else PinholeCovering.
PosedCamera RenderedCamera(const PosedCamera& target);

// `result`, rendered for `pinhole`, resampled into `camera`'s pixels (the same pose): color
// bilinear, depth and pixel classes nearest (never blended across an edge); a pixel whose ray
// falls outside the pinhole image, or whose distortion cannot be inverted, is out of view
// with color and depth 0. The hole metrics are recounted; the fill summary is kept.
void ResampleIntoDistorted(const Camera& camera, const Camera& pinhole, RenderResult* result);

}  // namespace parallax

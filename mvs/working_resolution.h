#pragma once
// The resolution the stereo works at, shared by the depth stage and fusion: each photo is
// resampled to `image_scale` of each side, and further so that its long side is at most
// `max_image_size` pixels (0: no cap).
#include "core/camera.h"

namespace parallax {

// The share of each side a width x height photo is worked at.
double WorkingScale(int width, int height, double image_scale, int max_image_size);

// The camera of a photo resampled to `scale` of its size: pixel coordinates (origin at the
// image corner) scale by the exact size ratio per axis.
Camera WorkingCamera(const Camera& camera, double scale);

}  // namespace parallax

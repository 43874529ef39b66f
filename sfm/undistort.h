#pragma once
// Undistortion of photos into PINHOLE cameras of the same size and intrinsics.
#include <filesystem>

#include "core/camera.h"

namespace parallax {

// The PINHOLE camera a photo of `camera` is undistorted into: same id, size, focal lengths
// and principal point.
Camera PinholeOf(const Camera& camera);

// Writes the photo at `input`, taken with `camera`, as PinholeOf(camera) would have taken it,
// to `output` (same format; JPEG at quality 100). Each pixel is resampled with Lanczos (8x8)
// where the distortion moved it: COLMAP's image_undistorter instead shrinks the image by a
// pixel (639x479 for 640x480, principal point moved by half a pixel), which resamples every
// pixel bilinearly at half-pixel offsets and blurs the photo even when the distortion is a
// tenth of a pixel (the courtyard's SIMPLE_RADIAL k = -0.0005). Pixels whose distorted
// position falls outside the photo (the corners, with a pincushion lens: k > 0) repeat its
// border; COLMAP would crop or rescale instead. Throws BadInputError naming the file when it
// cannot be read or written or is not of its camera's size, InternalError for a camera whose
// projection is not supported.
void UndistortPhoto(const Camera& camera, const std::filesystem::path& input,
                    const std::filesystem::path& output);

}  // namespace parallax

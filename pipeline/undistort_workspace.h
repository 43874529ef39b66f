#pragma once
// The undistort stage's output laid out as a workspace: the photos resampled into PINHOLE
// cameras (sfm/undistort.h), the model with those cameras, and the stereo/ folder COLMAP's
// dense tools read.
#include <filesystem>

#include "core/sparse_model.h"
#include "core/workspace.h"

namespace parallax {

// Writes what `colmap image_undistorter --output_type COLMAP` writes: the photos undistorted into
// PINHOLE cameras of the same size and intrinsics (copied as they are where a camera has no
// distortion; UndistortPhoto says why not COLMAP's resampling), the model with those cameras,
// and the stereo/ folder layout with the configuration files COLMAP's dense tools read, into
// `output`. Throws BadInputError naming a photo that cannot be read or a file that cannot be
// written.
void WritePinholeWorkspace(const SparseModel& model, const std::filesystem::path& photos_dir,
                           const Workspace& output);

}  // namespace parallax

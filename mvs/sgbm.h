#pragma once
// The baseline parallax's multi-view stereo is measured against: OpenCV's semi-global block
// matching (StereoSGBM) on rectified pairs. Each view is paired with its nearest source view
// whose rectified baseline runs horizontally to the right, rectified (cv::stereoRectify),
// matched, and the disparities are lifted to 3D and projected back into the view's own
// camera (z-buffer) as a depth map at pixel centres.
#include <filesystem>

#include "core/progress.h"
#include "mvs/mvs.h"

namespace parallax {

struct SgbmOptions {
  int block_size = 5;
  // Uniqueness margin (percent) and speckle filter of OpenCV's StereoSGBM.
  int uniqueness_ratio = 10;
  int speckle_window = 100;
  int speckle_range = 2;
  void Check() const;  // Throws std::invalid_argument naming the field and its value.
};

// Writes <ws>/depth/<stem>.exr and <stem>.confidence.exr (1 where SGBM found a disparity) for
// every view with a usable pair (after options.Check()); no normal maps (so fusion leaves SGBM views out). The plans
// (sources, depth ranges) come from the same view selection as multi-view stereo.
// Textureless windows (grey-level std below 0.004, PatchMatch's threshold) and windows that
// straddle the photo's edge get no depth: StereoSGBM alone would claim its minimum disparity
// all over a constant photo.
MvsSummary RunSgbmStereo(const std::filesystem::path& workspace, const ViewSelectionOptions& views,
                         const SgbmOptions& options, Progress& progress);

}  // namespace parallax

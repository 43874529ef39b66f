#pragma once
// The baseline parallax's multi-view stereo is measured against: OpenCV's semi-global block
// matching (StereoSGBM) on rectified pairs. Each view is paired with its nearest source view
// whose rectified baseline runs horizontally to the right, rectified (cv::stereoRectify),
// matched, and the disparities are lifted to 3D and projected back into the view's own
// camera (z-buffer) as a depth map at pixel centres. Over a workspace:
// pipeline/depth_workspace.h RunSgbmStereo.
#include <functional>
#include <optional>

#include "core/depth_map.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "mvs/mvs.h"
#include "mvs/view_selection.h"

namespace parallax {

struct SgbmOptions {
  int block_size = 5;
  // Uniqueness margin (percent) and speckle filter of OpenCV's StereoSGBM.
  int uniqueness_ratio = 10;
  int speckle_window = 100;
  int speckle_range = 2;
  void Check() const;  // Throws UsageError naming the field and its value.
};

struct SgbmViewDepth {
  DepthMap depth;       // At the photo's size; 0 where SGBM found no disparity.
  DepthMap confidence;  // 1 where it found one, else 0.
  MvsViewReport report;  // Its one source; both shares that of `depth`.
};

// The depth of `plan`'s view (a plan of the same view selection as multi-view stereo) from its
// first source view that rectifies to its right, or nullopt when none does (then no photo is
// read). `read_photo` returns an image's photo as read; the view's is read first, then its
// source's. Textureless windows (grey-level std below 0.004, PatchMatch's threshold) and
// windows that straddle the photo's edge get no depth: StereoSGBM alone would claim its
// minimum disparity all over a constant photo. Does not check `options` (SgbmOptions::Check).
std::optional<SgbmViewDepth> SgbmStereoView(const SparseModel& model, const ViewPlan& plan,
                                            const std::function<Image(const SparseImage&)>& read_photo,
                                            const SgbmOptions& options);

}  // namespace parallax

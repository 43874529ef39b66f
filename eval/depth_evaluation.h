#pragma once
// Measures estimated depth maps against ground truth (docs/design.md "evaluate's JSON", section
// "depth"). Depth is compared in the ground-truth cameras: each estimated pixel is lifted to
// 3D with its estimate camera, mapped by the similarity alignment into the ground-truth frame,
// projected into the same image's ground-truth camera and compared, as a z-depth, with the
// ground-truth depth where it lands.
//
// Over ground-truth-valid pixels (depth > 0): abs_rel = |d - d_gt| / d_gt,
// signed = (d - d_gt) / d_gt, within_Xpct = share with an estimate and abs_rel < X%,
// completeness = share with any estimate; medians are over the pixels with an estimate.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/sparse_model.h"
#include "geometry/similarity.h"

namespace parallax {

// The statistics of one set of ground-truth-valid pixels. Medians are 0 when no pixel has an
// estimate (completeness is then 0 as well); shares are 0 when no pixel is ground-truth-valid.
struct DepthErrors {
  double abs_rel_median = 0;
  double signed_median = 0;  // Bias: > 0 means the estimate lies too far.
  double within_1pct = 0;    // Share of ground-truth-valid pixels, in [0, 1].
  double within_2pct = 0;
  double completeness = 0;
};

struct DepthViewErrors : DepthErrors {
  std::string name;              // Image name, as in both models.
  int64_t gt_valid_pixels = 0;   // Pixels with ground-truth depth > 0.
  int64_t estimated_pixels = 0;  // Of those, the ones an estimate landed in.
};

struct DepthEvaluation : DepthErrors {
  int views = 0;  // Views compared: estimate depth present and the name in the ground truth.
  // Pooled over every ground-truth-valid pixel of every view (not a mean of the views).
  std::vector<DepthViewErrors> per_view;  // Sorted by name.
};

// Compares every image of `estimate_model` whose name is in `truth_model` and that has
// `<estimate_depth_dir>/<stem>.exr` (<stem> = name without extension) with
// `<truth_depth_dir>/<stem>.exr`; images without an estimate file are skipped.
//
// For a sub-pixel location the ground truth is the bilinear interpolation of inverse depth
// over the 4 nearest pixel centres when all 4 are > 0 and within 1% of each other (exact on
// planes), else the depth of the pixel the point lands in; where that is 0 (background) the
// estimate is not counted. When several estimated pixels land in one ground-truth pixel, the
// one nearest to the camera counts.
//
// With a non-empty `error_image_dir`, writes `<dir>/<stem>.png` per view (ground-truth camera
// size, sRGB 8-bit): abs_rel color-mapped (DepthErrorColor), black where the ground truth has
// depth but no estimate landed, mid grey where the ground truth has no depth.
//
// Throws BadInputError naming the file for a depth map whose size differs from its camera, a
// missing or unreadable ground-truth depth map, or a camera model parallax cannot project.
// Deterministic whatever the thread count.
DepthEvaluation EvaluateDepth(const SparseModel& estimate_model,
                              const std::filesystem::path& estimate_depth_dir,
                              const SparseModel& truth_model,
                              const std::filesystem::path& truth_depth_dir,
                              const Similarity3d& truth_from_estimate,
                              const std::filesystem::path& error_image_dir);

// The color (sRGB values in [0, 1]) of an abs_rel error in the error images: a ramp from
// dark blue (0) through teal and yellow-green (1%) and orange to red (2% and above).
Eigen::Vector3f DepthErrorColor(double abs_rel);

// The "depth" section of evaluate's JSON.
void AddDepthSection(const DepthEvaluation& evaluation, nlohmann::json& json);

}  // namespace parallax

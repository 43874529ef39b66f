#pragma once
// Accuracy of a 3D point set (fused cloud, mesh vertices) against ground-truth depth maps.
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "core/sparse_model.h"
#include "geometry/similarity.h"

namespace parallax {

struct CloudAccuracy {
  size_t points = 0;    // Points given.
  size_t measured = 0;  // Points some ground-truth view sees on a surface.
  double median_relative_distance = 0;  // Median over measured points.
  double within_1pct = 0;               // Share of measured points within 1%.
};

// Each point, mapped by `truth_from_estimate`, is projected into every ground-truth view; its
// relative distance |z - d_gt| / d_gt is the smallest over the views where it lands on a
// surface (truth depth > 0) and is not behind it by more than 5% (occluded). Deterministic.
CloudAccuracy MeasureCloud(const std::vector<Eigen::Vector3f>& points,
                           const SparseModel& truth_model,
                           const std::filesystem::path& truth_depth_dir,
                           const Similarity3d& truth_from_estimate);

}  // namespace parallax

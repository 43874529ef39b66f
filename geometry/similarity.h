#pragma once
// Similarity alignment of a reconstructed camera set to ground truth (or to any other frame):
// x_target = scale * R * x_source + t.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/pose.h"

namespace parallax {

struct Similarity3d {
  double scale = 1;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  // The pose of a camera whose source-frame pose is `cam_from_source`, in the target frame.
  Rigid3d TransformPose(const Rigid3d& cam_from_source) const;
  // The similarity taking the target frame back to the source frame.
  Similarity3d Inverse() const;
};

struct AlignmentOptions {
  // A camera is an inlier when its centre lands within this fraction of the target extent
  // (the largest distance between two target centres) ...
  double inlier_center_fraction = 0.05;
  // ... and its orientation within this angle, in degrees.
  double inlier_rotation_deg = 5;
  // Scale of the robust (Cauchy) loss on centre residuals, as a fraction of the extent.
  double robust_center_fraction = 0.01;
  // Scale of the robust loss on orientation residuals, in degrees.
  double robust_rotation_deg = 1;
  void Check() const;  // Throws UsageError naming the field.
};

struct AlignmentResult {
  Similarity3d target_from_source;
  int inliers = 0;
  double final_cost = 0;  // Robust cost after refinement, for diagnostics.
};

// Estimates target_from_source from corresponding camera poses (cam_from_world in each frame):
// a closed-form start (Umeyama on the centres, and a robust start from the orientations, which
// stays determined for collinear centres), refined with Ceres over centres and orientations
// under a robust loss, in normalised coordinates (so scales of 1e-8..1e8 and offsets of 1e6
// are as well-conditioned as unit ones).
// Throws InternalError for different counts, fewer than 3 cameras, or target centres
// that all coincide (the scale is then undetermined).
AlignmentResult AlignSimilarity(const std::vector<Rigid3d>& source_cams,
                                const std::vector<Rigid3d>& target_cams,
                                const AlignmentOptions& options = {});

}  // namespace parallax
